//! The recorded message topics, typed, in the order the recorder takes them each turn
//! (`harvey_msgs::topics::ALL`'s order; the camera's frames, last there, are a frame topic
//! apart). The recorder and the in-process replay both walk this list, so the two record a
//! tick's messages in the same order.

use harvey_cdr::Ros2Msg;
use harvey_msgs::topics::{self, Topic};

/// What walks the recorded message topics.
pub trait TopicVisitor {
    type Error;
    fn message<T: harvey_msgs::Message + Ros2Msg>(&mut self, topic: Topic<T>) -> Result<(), Self::Error>;
}

/// Hands `v` every recorded message topic in the recorder's order.
pub fn visit_message_topics<V: TopicVisitor>(v: &mut V) -> Result<(), V::Error> {
    v.message(topics::SIM_TRUTH)?;
    v.message(topics::DRV_SONAR_RAW)?;
    v.message(topics::DRV_ENCODERS_RAW)?;
    v.message(topics::VEHICLE_COMMAND)?;
    v.message(topics::VEHICLE_REFLEX)?;
    v.message(topics::SONAR_RING)?;
    v.message(topics::ODOMETRY)?;
    v.message(topics::VISION_DETECTIONS)?;
    v.message(topics::UMS_MAP)?;
    v.message(topics::VISION_SIGHTINGS)?;
    v.message(topics::UMS_EXPECTATIONS)?;
    v.message(topics::EXECUTIVE_STATUS)?;
    v.message(topics::EXECUTIVE_SERVO)?;
    v.message(topics::EXECUTIVE_POSE)?;
    v.message(topics::EXECUTIVE_PLAN)?;
    v.message(topics::EXECUTIVE_BEHAVIOUR)?;
    v.message(topics::VISION_REQUESTS)?;
    v.message(topics::VISION_RESULTS)?;
    v.message(topics::ROSOUT)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Names(Vec<&'static str>);

    impl TopicVisitor for Names {
        type Error = ();
        fn message<T: harvey_msgs::Message + Ros2Msg>(&mut self, topic: Topic<T>) -> Result<(), ()> {
            self.0.push(topic.name);
            Ok(())
        }
    }

    #[test]
    fn every_topic_but_the_frames_in_the_order_of_all() {
        let mut names = Names(Vec::new());
        visit_message_topics(&mut names).expect("visits");
        names.0.push(topics::CAMERA_FRAME.name);
        assert_eq!(names.0, topics::ALL);
    }
}
