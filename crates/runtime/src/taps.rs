//! Taps on every topic for the bridges (Foxglove, Zenoh): one subscription per Harvey topic,
//! each message handed over in CDR exactly as the recorder writes it (`harvey_cdr::encode`,
//! `encode_image`) with its `ros2msg` schema (`harvey_cdr::full_text`), when asked for: a camera
//! frame's header comes with it either way, read in place.

use harvey_bus::{Bus, FrameSubscriber, Origin, Subscriber, Waitable};
use harvey_cdr::{Def, Ros2Msg, encode, encode_image, full_text, image_def};
use harvey_msgs::{FrameHeader, Message, Qos, Topic, topics};

/// One message taken from a topic.
pub struct Taken<'a> {
    /// The publisher's sequence number (a frame's too, which its CDR has no field for).
    pub seq: u64,
    pub stamp_ns: u64,
    /// The message in CDR; empty when the caller did not ask for it.
    pub cdr: &'a [u8],
    /// A camera frame's header, read in place, and its pixels' length, encoded or not: what
    /// the camera's calibration is derived from. `None` for other messages.
    pub frame: Option<(FrameHeader, usize)>,
}

/// A subscribed topic, whatever its type.
pub trait Tap {
    /// The Harvey topic name (`sonar/ring`, no leading `/`).
    fn topic(&self) -> &'static str;
    /// The ROS 2 definition its messages are encoded by.
    fn def(&self) -> &'static Def;
    fn waitable(&self) -> &dyn Waitable;
    /// Hands every queued message to `f`, encoded into `buf` (reused) when `encode` is true;
    /// returns how many. Messages not encoded are still taken, so the queue never fills up.
    fn take(&self, encode: bool, buf: &mut Vec<u8>, f: &mut dyn FnMut(Taken)) -> anyhow::Result<usize>;
    /// Hands every queued message but those `skip` says no to by their publisher to `f` as
    /// `(publisher, seq, stamp_ns, CDR)`, each encoded into a buffer of its own that `f` keeps (a frame's
    /// pixels copied once, out of shared memory, and no more); returns how many were taken.
    fn take_owned(
        &self,
        skip: &dyn Fn(Origin) -> bool,
        f: &mut dyn FnMut(Origin, u64, u64, Vec<u8>),
    ) -> anyhow::Result<usize>;
}

/// The topic's schema as Foxglove and MCAP want it: `pkg/msg/Type` and the full `ros2msg` text.
pub fn schema_of(def: &Def) -> (String, String) {
    (def.schema_name(), full_text(def))
}

struct MsgTap<T: Message> {
    sub: Subscriber<T>,
}

impl<T: Message + Ros2Msg> Tap for MsgTap<T> {
    fn topic(&self) -> &'static str {
        self.sub.topic()
    }

    fn def(&self) -> &'static Def {
        T::DEF
    }

    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }

    fn take(&self, want: bool, buf: &mut Vec<u8>, f: &mut dyn FnMut(Taken)) -> anyhow::Result<usize> {
        Ok(self.sub.drain(|m| {
            let h = *m.header();
            if want {
                *buf = encode(m, std::mem::take(buf));
            }
            let cdr = if want { buf.as_slice() } else { &[] };
            f(Taken { seq: h.seq, stamp_ns: h.stamp_ns, cdr, frame: None });
        })?)
    }

    fn take_owned(
        &self,
        skip: &dyn Fn(Origin) -> bool,
        f: &mut dyn FnMut(Origin, u64, u64, Vec<u8>),
    ) -> anyhow::Result<usize> {
        Ok(self.sub.drain_with_origin(|m, from| {
            if !skip(from) {
                let h = *m.header();
                f(from, h.seq, h.stamp_ns, encode(m, Vec::new()));
            }
        })?)
    }
}

struct FrameTap {
    sub: FrameSubscriber,
}

impl Tap for FrameTap {
    fn topic(&self) -> &'static str {
        self.sub.topic()
    }

    fn def(&self) -> &'static Def {
        image_def()
    }

    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }

    fn take(&self, want: bool, buf: &mut Vec<u8>, f: &mut dyn FnMut(Taken)) -> anyhow::Result<usize> {
        // At most a queue's worth per wake-up, as the recorder does: a camera going flat out
        // must not keep this loop from the other topics.
        let mut n = 0;
        while n < Qos::FRAMES.buffer
            && let Some(frame) = self.sub.take()?
        {
            let (h, pixel_bytes) = (*frame.header(), frame.pixels().len());
            if want {
                *buf = encode_image(&h, frame.pixels(), std::mem::take(buf));
            }
            // The slot goes back to the camera before the frame is sent on.
            drop(frame);
            let cdr = if want { buf.as_slice() } else { &[] };
            f(Taken { seq: h.seq, stamp_ns: h.stamp_ns, cdr, frame: Some((h, pixel_bytes)) });
            n += 1;
        }
        Ok(n)
    }

    fn take_owned(
        &self,
        skip: &dyn Fn(Origin) -> bool,
        f: &mut dyn FnMut(Origin, u64, u64, Vec<u8>),
    ) -> anyhow::Result<usize> {
        let mut n = 0;
        while n < Qos::FRAMES.buffer
            && let Some(frame) = self.sub.take()?
        {
            let from = frame.origin();
            if skip(from) {
                continue;
            }
            let h = *frame.header();
            let cdr = encode_image(&h, frame.pixels(), Vec::new());
            drop(frame);
            f(from, h.seq, h.stamp_ns, cdr);
            n += 1;
        }
        Ok(n)
    }
}

fn tap<T: Message + Ros2Msg>(bus: &Bus, topic: Topic<T>) -> anyhow::Result<Box<dyn Tap>> {
    Ok(Box::new(MsgTap { sub: bus.subscriber(topic)? }))
}

/// Subscribes to every topic of [`topics::ALL`], in that order. Fails if one is missing here.
pub fn open_all(bus: &Bus) -> anyhow::Result<Vec<Box<dyn Tap>>> {
    open(bus, |_| true)
}

/// Subscribes to the topics of [`topics::ALL`] that `wanted` picks, in that order.
pub fn open(bus: &Bus, wanted: impl Fn(&str) -> bool) -> anyhow::Result<Vec<Box<dyn Tap>>> {
    let taps: Vec<Box<dyn Tap>> = vec![
        tap(bus, topics::SIM_TRUTH)?,
        tap(bus, topics::DRV_SONAR_RAW)?,
        tap(bus, topics::DRV_ENCODERS_RAW)?,
        tap(bus, topics::VEHICLE_COMMAND)?,
        tap(bus, topics::VEHICLE_REFLEX)?,
        tap(bus, topics::SONAR_RING)?,
        tap(bus, topics::ODOMETRY)?,
        tap(bus, topics::VISION_DETECTIONS)?,
        tap(bus, topics::UMS_MAP)?,
        tap(bus, topics::VISION_SIGHTINGS)?,
        tap(bus, topics::UMS_EXPECTATIONS)?,
        tap(bus, topics::EXECUTIVE_STATUS)?,
        tap(bus, topics::EXECUTIVE_SERVO)?,
        tap(bus, topics::EXECUTIVE_POSE)?,
        tap(bus, topics::EXECUTIVE_PLAN)?,
        tap(bus, topics::EXECUTIVE_BEHAVIOUR)?,
        tap(bus, topics::VISION_REQUESTS)?,
        tap(bus, topics::VISION_RESULTS)?,
        tap(bus, topics::ROSOUT)?,
        Box::new(FrameTap { sub: bus.frame_subscriber(topics::CAMERA_FRAME)? }),
    ];
    let tapped: Vec<&str> = taps.iter().map(|t| t.topic()).collect();
    let missing: Vec<&&str> = topics::ALL.iter().filter(|t| !tapped.contains(t)).collect();
    anyhow::ensure!(missing.is_empty(), "the bridges have no tap for {missing:?}");
    Ok(taps.into_iter().filter(|t| wanted(t.topic())).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::{Header, Odometry};

    #[test]
    fn every_topic_is_tapped_with_a_schema_its_messages_decode_by() {
        let prefix = format!("trttaps{}_", std::process::id());
        let bus = Bus::join_with_prefix("taps-test", &prefix).expect("bus");
        let taps = open_all(&bus).expect("taps");
        let names: Vec<&str> = taps.iter().map(|t| t.topic()).collect();
        assert_eq!(names, topics::ALL);
        for t in &taps {
            let (name, text) = schema_of(t.def());
            assert!(name.contains("/msg/"), "{name}");
            harvey_cdr::Schema::parse(&name, &text).unwrap_or_else(|e| panic!("{}: {e}", t.topic()));
        }

        let odometry = bus.publisher(topics::ODOMETRY).expect("publisher");
        let sent = Odometry { header: Header::new(7, 350_000_000), travelled_m: 1.5, ..Default::default() };
        odometry.send(&sent).expect("send");
        let tap = taps.iter().find(|t| t.topic() == topics::ODOMETRY.name).expect("odometry tap");
        let (mut buf, mut got) = (Vec::new(), Vec::new());
        let n =
            tap.take(true, &mut buf, &mut |m| got.push((m.seq, m.stamp_ns, m.cdr.to_vec()))).expect("take");
        assert_eq!(n, 1);
        assert_eq!((got[0].0, got[0].1), (7, 350_000_000));
        assert_eq!(got[0].2, encode(&sent, Vec::new()), "the recorder's bytes");
        odometry.send(&sent).expect("send");
        let mut owned = Vec::new();
        assert_eq!(
            tap.take_owned(&|_| false, &mut |from, seq, stamp, cdr| {
                assert_eq!(from, odometry.origin());
                owned.push((seq, stamp, cdr))
            })
            .expect("take"),
            1
        );
        assert_eq!(owned, [(7, 350_000_000, encode(&sent, Vec::new()))], "the same bytes, owned");
        odometry.send(&sent).expect("send");
        let mine = odometry.origin();
        tap.take_owned(&|from| from == mine, &mut |_, _, _, _| {
            panic!("its own publisher's message is skipped")
        })
        .expect("take");
        odometry.send(&sent).expect("send");
        let n = tap.take(false, &mut buf, &mut |m| assert!(m.cdr.is_empty())).expect("take");
        assert_eq!(n, 1, "taken, not encoded");
        let some = open(&bus, |t| t.starts_with("vision/")).expect("some taps");
        let names: Vec<&str> = some.iter().map(|t| t.topic()).collect();
        assert_eq!(names, ["vision/detections", "vision/sightings", "vision/requests", "vision/results"]);
        drop((odometry, taps, some, bus));
        harvey_bus::retire_domain(&prefix).expect("retire");
    }
}
