//! A running domain's topic opened by name with its Harvey type: each message taken is handed
//! over with its stamp and, for `echo`, decoded as the recorder would record it (CDR, then read
//! back by the `ros2msg` schema alone, into JSON).

use harvey_bus::{Bus, FrameSubscriber, Subscriber, Waitable};
use harvey_cdr::{Ros2Msg, Schema, encode, full_text};
use harvey_msgs::{Message, Topic, topics};
use serde_json::{Value, json};

/// One message taken from a topic.
pub struct Taken {
    pub stamp_ns: u64,
    /// The decoded message, when asked for.
    pub value: Option<Value>,
}

/// A topic a tool subscribes to without knowing its type at compile time.
pub trait Source {
    fn waitable(&self) -> &dyn Waitable;
    /// Hands every queued message to `f`; returns how many.
    fn take(&self, decode: bool, f: &mut dyn FnMut(Taken)) -> anyhow::Result<usize>;
}

struct Messages<T: Message + Ros2Msg> {
    sub: Subscriber<T>,
    schema: Schema,
}

impl<T: Message + Ros2Msg> Source for Messages<T> {
    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }

    fn take(&self, decode: bool, f: &mut dyn FnMut(Taken)) -> anyhow::Result<usize> {
        let mut failed = None;
        let n = self.sub.drain(|m| {
            let value = decode.then(|| self.schema.decode(&encode(m, Vec::new())));
            let value = match value.transpose() {
                Ok(v) => v,
                Err(e) => {
                    failed.get_or_insert(e);
                    None
                }
            };
            f(Taken { stamp_ns: m.header().stamp_ns, value });
        })?;
        match failed {
            Some(e) => {
                Err(anyhow::anyhow!("{}: a message does not decode by its schema: {e}", self.sub.topic()))
            }
            None => Ok(n),
        }
    }
}

struct Frames {
    sub: FrameSubscriber,
}

impl Source for Frames {
    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }

    /// A frame is shown by its `sensor_msgs/msg/Image` fields, the pixels by their count.
    fn take(&self, decode: bool, f: &mut dyn FnMut(Taken)) -> anyhow::Result<usize> {
        let mut n = 0;
        while let Some(frame) = self.sub.take()? {
            let h = *frame.header();
            let value = decode.then(|| {
                json!({
                    "header": {
                        "stamp": {"sec": h.stamp_ns / 1_000_000_000, "nanosec": h.stamp_ns % 1_000_000_000},
                        "frame_id": "camera",
                    },
                    "height": h.height_px,
                    "width": h.width_px,
                    "encoding": h.encoding().map_or("?", |e| e.ros_name()),
                    "step": h.stride_bytes,
                    "data": format!("<{} bytes>", frame.pixels().len()),
                })
            });
            drop(frame);
            f(Taken { stamp_ns: h.stamp_ns, value });
            n += 1;
        }
        Ok(n)
    }
}

fn messages<T: Message + Ros2Msg>(bus: &Bus, topic: Topic<T>) -> anyhow::Result<Box<dyn Source>> {
    let schema = Schema::parse(&T::DEF.schema_name(), &full_text(T::DEF))?;
    Ok(Box::new(Messages { sub: bus.subscriber(topic)?, schema }))
}

/// Subscribes to Harvey topic `name` (without a leading `/`).
pub fn open(bus: &Bus, name: &str) -> anyhow::Result<Box<dyn Source>> {
    macro_rules! typed {
        ($($t:expr),* $(,)?) => {$(
            if name == $t.name {
                return messages(bus, $t);
            }
        )*};
    }
    typed!(
        topics::SIM_TRUTH,
        topics::DRV_SONAR_RAW,
        topics::DRV_ENCODERS_RAW,
        topics::VEHICLE_COMMAND,
        topics::VEHICLE_REFLEX,
        topics::SONAR_RING,
        topics::ODOMETRY,
        topics::VISION_DETECTIONS,
        topics::UMS_MAP,
        topics::VISION_SIGHTINGS,
        topics::UMS_EXPECTATIONS,
        topics::EXECUTIVE_STATUS,
        topics::EXECUTIVE_SERVO,
        topics::EXECUTIVE_POSE,
        topics::EXECUTIVE_PLAN,
        topics::EXECUTIVE_BEHAVIOUR,
        topics::VISION_REQUESTS,
        topics::VISION_RESULTS,
        topics::ROSOUT,
    );
    if name == topics::CAMERA_FRAME.name {
        return Ok(Box::new(Frames { sub: bus.frame_subscriber(topics::CAMERA_FRAME)? }));
    }
    if name.starts_with("clock/") {
        anyhow::bail!("`{name}` is the clock chain's plumbing, not data: it is not decoded");
    }
    anyhow::bail!("`{name}` is not one of Harvey's topics ({})", topics::ALL.join(", "))
}
