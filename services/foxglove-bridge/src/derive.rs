//! The hook for derived channels: messages computed from the bus messages (`/tf`, `/tf_static`,
//! `/markers`, ...) and published beside them. Each bus message of a topic the [`Derive`] wants
//! is offered to it as (topic, stamp, CDR bytes), and each camera frame's header, read in place,
//! as it is (the pixels are not encoded for it); what it returns is published on a channel of
//! its own, created on first use with the message's `ros2msg` schema.
//!
//! [`hook`] derives what the recorder derives (`harvey_recording::derive`: `/tf`, `/tf_static`,
//! the markers and `/camera/camera_info`, the latter from the frame's header alone), from the
//! messages the bridge takes, in the order it takes them. Topics not advertised up front are
//! created on first use, not latched.
//!
//! Latched channels: a client that subscribes late still gets the last message of a channel
//! whose messages hold until replaced (`/tf_static`, the map's markers: ROS's transient-local
//! durability). The bridge keeps that message in [`Latched`]; the server's listener hands it to
//! each new subscriber of the channel, to that client alone.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, PoisonError};

use foxglove::websocket::{ChannelView, Client, ServerListener};
use foxglove::{ChannelId, PartialMetadata, RawChannel};
use harvey_cdr::Def;
use harvey_msgs::{FrameHeader, topics};
use harvey_recording::derive::{self, Deriver};
use harvey_world::World;

/// One derived message to publish.
#[derive(Debug, Clone)]
pub struct Derived {
    /// The channel's topic, with its leading `/` (`/tf`).
    pub topic: String,
    /// The ROS 2 definition of `cdr` (e.g. `tf2_msgs/TFMessage`): the channel's schema.
    pub def: &'static Def,
    /// Log time: normally the stamp of the bus message it came from.
    pub stamp_ns: u64,
    /// The message in CDR.
    pub cdr: Vec<u8>,
}

/// Computes derived messages from the bus messages.
pub trait Derive {
    /// Whether messages of `topic` (`odometry`, no leading `/`) are wanted in CDR: those are
    /// encoded and offered even while no client is subscribed to the topic itself.
    fn wants(&self, topic: &str) -> bool;

    /// Offered one message of a wanted topic (in CDR, as recorded); pushes onto `out` what it
    /// derives from it, if anything.
    fn derive(
        &mut self,
        topic: &str,
        stamp_ns: u64,
        cdr: &[u8],
        out: &mut Vec<Derived>,
    ) -> anyhow::Result<()>;

    /// Offered the header of each camera frame, read in place (its pixels `pixel_bytes` long),
    /// whether or not anyone watches the frames; pushes onto `out` what it derives from it.
    fn derive_frame(
        &mut self,
        _h: &FrameHeader,
        _pixel_bytes: usize,
        _out: &mut Vec<Derived>,
    ) -> anyhow::Result<()> {
        Ok(())
    }

    /// The derived topics to advertise before their first message, with their definitions and
    /// whether they are latched: a client that subscribes late still gets the last message
    /// (`/tf_static`, the map; `harvey_recording::derive::TOPICS` says which).
    fn advertised(&self) -> Vec<(String, &'static Def, bool)> {
        Vec::new()
    }
}

/// What the recorder derives, derived live: with the run's world, the map's markers and the
/// camera's height too.
pub fn hook(world: Option<&World>) -> Box<dyn Derive> {
    Box::new(Recorded { deriver: Deriver::new(world), out: Vec::new() })
}

/// `harvey_recording::derive` behind the bridge's [`Derive`].
struct Recorded {
    deriver: Deriver,
    out: Vec<derive::Derived>,
}

/// The bus topics the derived ones come from in CDR (the camera's calibration comes from each
/// frame's header: [`Derive::derive_frame`]).
const SOURCES: [&str; 5] = [
    topics::SIM_TRUTH.name,
    topics::ODOMETRY.name,
    topics::EXECUTIVE_STATUS.name,
    topics::UMS_MAP.name,
    topics::EXECUTIVE_PLAN.name,
];

impl Derive for Recorded {
    fn wants(&self, topic: &str) -> bool {
        SOURCES.contains(&topic)
    }

    fn derive(
        &mut self,
        topic: &str,
        stamp_ns: u64,
        cdr: &[u8],
        out: &mut Vec<Derived>,
    ) -> anyhow::Result<()> {
        self.deriver
            .derive(topic, stamp_ns, cdr, &mut self.out)
            .map_err(|e| anyhow::anyhow!("deriving from {topic}: {e}"))?;
        self.hand_over(out)
    }

    fn derive_frame(
        &mut self,
        h: &FrameHeader,
        pixel_bytes: usize,
        out: &mut Vec<Derived>,
    ) -> anyhow::Result<()> {
        self.deriver
            .derive_frame(h, pixel_bytes, &mut self.out)
            .map_err(|e| anyhow::anyhow!("deriving from {}: {e}", topics::CAMERA_FRAME.name))?;
        self.hand_over(out)
    }

    fn advertised(&self) -> Vec<(String, &'static Def, bool)> {
        derive::TOPICS.iter().map(|&(topic, def, latched)| (format!("/{topic}"), def, latched)).collect()
    }
}

impl Recorded {
    /// Moves what the deriver made onto `out`, with each topic's definition.
    fn hand_over(&mut self, out: &mut Vec<Derived>) -> anyhow::Result<()> {
        for d in self.out.drain(..) {
            let def = derive::index(d.topic).map(|k| derive::TOPICS[k].1);
            let def = def.ok_or_else(|| anyhow::anyhow!("{} is not a derived topic", d.topic))?;
            out.push(Derived { topic: format!("/{}", d.topic), def, stamp_ns: d.stamp_ns, cdr: d.data });
        }
        Ok(())
    }
}

/// A latched channel's last message: the channel, its log time, its bytes.
type Last = (Arc<RawChannel>, u64, Vec<u8>);

/// The last message of each latched channel.
#[derive(Default)]
pub struct Latched {
    last: Mutex<HashMap<ChannelId, Last>>,
}

impl Latched {
    /// Keeps `cdr`, logged at `stamp_ns`, as `channel`'s message for late subscribers.
    pub fn keep(&self, channel: &Arc<RawChannel>, stamp_ns: u64, cdr: &[u8]) {
        let mut last = self.last.lock().unwrap_or_else(PoisonError::into_inner);
        match last.get_mut(&channel.id()) {
            Some((_, at, data)) => {
                *at = stamp_ns;
                data.clear();
                data.extend_from_slice(cdr);
            }
            None => {
                last.insert(channel.id(), (channel.clone(), stamp_ns, cdr.to_vec()));
            }
        }
    }

    /// How many channels hold a latched message.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.last.lock().unwrap_or_else(PoisonError::into_inner).len()
    }
}

impl ServerListener for Latched {
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        let last = self.last.lock().unwrap_or_else(PoisonError::into_inner);
        if let (Some((ch, stamp_ns, data)), Some(sink)) = (last.get(&channel.id()), client.sink_id()) {
            ch.log_with_meta_to_sink(data, PartialMetadata::with_log_time(*stamp_ns), Some(sink));
        }
    }
}

#[cfg(test)]
pub mod tests {
    use super::*;

    /// A stand-in derivation for the tests: every odometry message yields one `/odometry_copy`
    /// message of the same bytes, and a latched `/static` is advertised from the start.
    pub struct Copy;

    impl Derive for Copy {
        fn wants(&self, topic: &str) -> bool {
            topic == "odometry"
        }

        fn derive(
            &mut self,
            topic: &str,
            stamp_ns: u64,
            cdr: &[u8],
            out: &mut Vec<Derived>,
        ) -> anyhow::Result<()> {
            anyhow::ensure!(topic == "odometry", "offered {topic}, which it does not want");
            let def = <harvey_msgs::Odometry as harvey_cdr::Ros2Msg>::DEF;
            out.push(Derived { topic: "/odometry_copy".into(), def, stamp_ns, cdr: cdr.to_vec() });
            Ok(())
        }

        fn advertised(&self) -> Vec<(String, &'static Def, bool)> {
            vec![("/static".into(), <harvey_msgs::TruePose as harvey_cdr::Ros2Msg>::DEF, true)]
        }
    }

    #[test]
    fn the_hook_derives_what_the_recorder_derives() {
        let mut h = hook(None);
        let mut out = Vec::new();
        assert!(h.wants("odometry") && !h.wants("sonar/ring"));
        let odometry =
            harvey_msgs::Odometry { header: harvey_msgs::Header::new(1, 50), ..Default::default() };
        h.derive("odometry", 50, &harvey_cdr::encode(&odometry, Vec::new()), &mut out).expect("derive");
        let topics: Vec<&str> = out.iter().map(|d| d.topic.as_str()).collect();
        assert_eq!(topics, ["/tf_static", "/tf"]);
        let advertised = h.advertised();
        assert!(advertised.iter().any(|(t, _, latched)| t == "/tf_static" && *latched), "{advertised:?}");
        assert!(h.derive("odometry", 60, &[0, 1, 0, 0], &mut out).is_err(), "garbled bytes are an error");
    }

    pub fn world() -> World {
        let text = include_str!("../../../worlds/hallway.toml");
        harvey_world::load_str(text, "hallway.toml").expect("the hallway world loads")
    }

    #[test]
    fn a_frame_header_brings_the_calibration_the_recorder_derives_from_the_frame() {
        let world = world();
        let frame = harvey_msgs::FrameHeader::new(2, 100_000_000, 640, 480, harvey_msgs::Encoding::Mono8);
        let pixels = vec![0u8; frame.payload_len()];
        let mut h = hook(Some(&world));
        assert!(!h.wants(topics::CAMERA_FRAME.name), "frames are not encoded for the hook");
        let mut out = Vec::new();
        h.derive_frame(&frame, pixels.len(), &mut out).expect("derive");
        let mut recorder = Deriver::new(Some(&world));
        let mut recorded = Vec::new();
        let cdr = harvey_cdr::encode_image(&frame, &pixels, Vec::new());
        recorder.derive(topics::CAMERA_FRAME.name, frame.stamp_ns, &cdr, &mut recorded).expect("recorder");
        let served: Vec<(String, u64, &[u8])> =
            out.iter().map(|d| (d.topic.clone(), d.stamp_ns, d.cdr.as_slice())).collect();
        let recorded: Vec<(String, u64, &[u8])> =
            recorded.iter().map(|d| (format!("/{}", d.topic), d.stamp_ns, d.data.as_slice())).collect();
        assert_eq!(served, recorded, "the recorder's messages, byte for byte");
        assert!(served.iter().any(|(t, ..)| t == "/camera/camera_info"), "{served:?}");
        let garbled = harvey_msgs::FrameHeader { encoding: 9, ..frame };
        assert!(h.derive_frame(&garbled, pixels.len(), &mut out).is_err(), "as the recorder refuses it");
    }

    #[test]
    fn the_last_message_of_a_channel_is_kept() {
        let def = <harvey_msgs::TruePose as harvey_cdr::Ros2Msg>::DEF;
        let ch = crate::bridge::channel("/latched_test", def).expect("channel");
        let latched = Latched::default();
        latched.keep(&ch, 1, &[1, 2, 3]);
        latched.keep(&ch, 2, &[4]);
        assert_eq!(latched.len(), 1);
        let last = latched.last.lock().expect("lock");
        let (_, at, data) = last.get(&ch.id()).expect("kept");
        assert_eq!((*at, data.as_slice()), (2, &[4u8][..]));
    }
}
