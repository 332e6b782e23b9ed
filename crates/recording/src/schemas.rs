//! Whether a recording's message definitions are this build's. A replay feeds the services the
//! recorded bytes: a recording made by a Harvey whose messages were laid out otherwise would be
//! read into a wrong answer, so a replay refuses it, naming the topics that differ.

use std::collections::BTreeMap;

use harvey_cdr::{Def, Ros2Msg, full_text, image_def};
use harvey_msgs::topics::{self, Topic};

use crate::topics::{TopicVisitor, visit_message_topics};
use crate::{Recording, RecordingError, derive};

/// This build's schema (name, full text) of every recorded topic.
fn ours() -> BTreeMap<&'static str, (String, String)> {
    struct Collect(BTreeMap<&'static str, (String, String)>);
    impl TopicVisitor for Collect {
        type Error = std::convert::Infallible;
        fn message<T: harvey_msgs::Message + Ros2Msg>(&mut self, topic: Topic<T>) -> Result<(), Self::Error> {
            self.0.insert(topic.name, schema(T::DEF));
            Ok(())
        }
    }
    fn schema(def: &Def) -> (String, String) {
        (def.schema_name(), full_text(def))
    }
    let mut c = Collect(BTreeMap::new());
    // Infallible: the visitor cannot fail.
    let _ = visit_message_topics(&mut c);
    c.0.insert(topics::CAMERA_FRAME.name, schema(image_def()));
    for (topic, def, _) in derive::TOPICS {
        c.0.insert(topic, schema(def));
    }
    c.0
}

/// The recorded topics whose message definition is not this build's (or that this build does
/// not know), each said for a person; empty when the recording replays as it was made.
pub fn differences(recording: &Recording) -> Result<Vec<String>, RecordingError> {
    let ours = ours();
    let mut out = Vec::new();
    for channel in recording.summary()?.channels.values() {
        let topic = channel.topic.trim_start_matches('/');
        let Some(schema) = &channel.schema else { continue };
        match ours.get(topic) {
            Some((name, text)) if *name == schema.name && text.as_bytes() == &schema.data[..] => {}
            Some((name, _)) if *name == schema.name => out
                .push(format!("{}: {} is defined otherwise than in this build", channel.topic, schema.name)),
            Some((name, _)) => {
                out.push(format!("{}: recorded as {}, this build has {name}", channel.topic, schema.name))
            }
            None => out.push(format!("{}: not a topic of this build", channel.topic)),
        }
    }
    // The summary's channels come in no set order: said by topic.
    out.sort();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    static OTHER_COMMAND: Def =
        Def { name: "harvey_msgs/MotionCommand", text: "uint32 kind\nfloat32 distance_m\n", deps: &[] };

    #[test]
    fn a_message_laid_out_otherwise_is_named() {
        let dir = std::env::temp_dir().join(format!("harvey-schemas-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let (same, other) = (dir.join("same.mcap"), dir.join("other.mcap"));
        let mut r = crate::Recorder::create(&same).expect("create");
        r.channel::<harvey_msgs::MotionCommand>(topics::VEHICLE_COMMAND.name).expect("channel");
        r.image_channel(topics::CAMERA_FRAME.name).expect("frames");
        r.derived_channels().expect("derived");
        r.finish().expect("finish");
        assert_eq!(
            differences(&Recording::open(&same).expect("opens")).expect("reads"),
            Vec::<String>::new()
        );
        let mut r = crate::Recorder::create(&other).expect("create");
        r.add_channel_for_test(topics::VEHICLE_COMMAND.name, &OTHER_COMMAND);
        r.add_channel_for_test("odometry2", <harvey_msgs::Odometry as Ros2Msg>::DEF);
        r.finish().expect("finish");
        let d = differences(&Recording::open(&other).expect("opens")).expect("reads");
        assert_eq!(
            d,
            [
                "/odometry2: not a topic of this build",
                "/vehicle/command: harvey_msgs/msg/MotionCommand is defined otherwise than in this build"
            ]
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
