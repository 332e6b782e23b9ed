//! How each message type is drawn in the Rerun recording (see `rrd.rs`); types with nothing to
//! draw are left out of the view.

use harvey_msgs::{
    Detections, EncodersRaw, Expectation, LandmarkSighting, MissionStatus, MotionCommand, Odometry,
    ServoCorrection, SonarRaw, SonarRing, TruePose, UncertaintyMap, VisionRequest, VisionResult,
};

use crate::RecordError;
use crate::rrd::RrdWriter;

/// A message that knows how to show itself in Rerun.
pub trait Draw {
    fn draw(&self, w: &mut RrdWriter) -> Result<(), RecordError>;
}

macro_rules! draw_with {
    ($($t:ty => $method:ident),* $(,)?) => {$(
        impl Draw for $t {
            fn draw(&self, w: &mut RrdWriter) -> Result<(), RecordError> {
                w.$method(self)
            }
        }
    )*};
}

draw_with!(
    TruePose => truth,
    Odometry => odometry,
    SonarRing => sonar,
    UncertaintyMap => map,
    Expectation => expectation,
    LandmarkSighting => sighting,
    MotionCommand => command,
    MissionStatus => status,
    ServoCorrection => servo,
    harvey_msgs::PoseFix => pose_fix,
    harvey_msgs::PlanSketch => plan,
    harvey_msgs::BehaviourState => behaviour,
    Detections => detections,
    VisionResult => vision_result,
);

/// Requests are in the MCAP file; the view shows their results.
impl Draw for VisionRequest {
    fn draw(&self, _: &mut RrdWriter) -> Result<(), RecordError> {
        Ok(())
    }
}

/// Raw DRV reports are in the MCAP file; the view shows their refined forms.
impl Draw for SonarRaw {
    fn draw(&self, _: &mut RrdWriter) -> Result<(), RecordError> {
        Ok(())
    }
}

impl Draw for EncodersRaw {
    fn draw(&self, _: &mut RrdWriter) -> Result<(), RecordError> {
        Ok(())
    }
}
