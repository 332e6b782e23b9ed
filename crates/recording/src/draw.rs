//! How each message type is drawn in the Rerun recording (see `rrd.rs`); types with nothing to
//! draw are left out of the view. [`draw_recorded`] draws a recorded message by its topic: the
//! live recorder and `harvey export` both go through it.

use harvey_cdr::{CdrError, Ros2Msg, decode, decode_image};
use harvey_msgs::{
    Detections, EncodersRaw, Expectation, LandmarkSighting, MissionStatus, MotionCommand, Odometry,
    ServoCorrection, SonarRaw, SonarRing, TruePose, UncertaintyMap, VisionRequest, VisionResult, topics,
};

use crate::rrd::{RrdError, RrdWriter};

/// A recorded message that could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum DrawError {
    /// The payload does not decode as its topic's type.
    #[error("{0}")]
    Decode(#[from] CdrError),
    /// The Rerun file failed.
    #[error("{0}")]
    Rrd(#[from] RrdError),
}

/// A message that knows how to show itself in Rerun.
pub trait Draw {
    fn draw(&self, w: &mut RrdWriter) -> Result<(), RrdError>;
}

macro_rules! draw_with {
    ($($t:ty => $method:ident),* $(,)?) => {$(
        impl Draw for $t {
            fn draw(&self, w: &mut RrdWriter) -> Result<(), RrdError> {
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
    harvey_msgs::LogLine => rosout,
);

/// Requests are in the MCAP file; the view shows their results.
impl Draw for VisionRequest {
    fn draw(&self, _: &mut RrdWriter) -> Result<(), RrdError> {
        Ok(())
    }
}

/// Raw DRV reports are in the MCAP file; the view shows their refined forms.
impl Draw for SonarRaw {
    fn draw(&self, _: &mut RrdWriter) -> Result<(), RrdError> {
        Ok(())
    }
}

impl Draw for EncodersRaw {
    fn draw(&self, _: &mut RrdWriter) -> Result<(), RrdError> {
        Ok(())
    }
}

fn draw<T: Ros2Msg + Draw>(w: &mut RrdWriter, data: &[u8]) -> Result<(), DrawError> {
    let msg: T = decode(data)?;
    Ok(msg.draw(w)?)
}

/// Draws one recorded message; topics Harvey does not know are skipped (`Ok(false)`).
pub fn draw_recorded(w: &mut RrdWriter, topic: &str, data: &[u8]) -> Result<bool, DrawError> {
    let t = topic.trim_start_matches('/');
    match t {
        _ if t == topics::SIM_TRUTH.name => draw::<TruePose>(w, data)?,
        _ if t == topics::DRV_SONAR_RAW.name => draw::<SonarRaw>(w, data)?,
        _ if t == topics::DRV_ENCODERS_RAW.name => draw::<EncodersRaw>(w, data)?,
        _ if t == topics::VEHICLE_COMMAND.name || t == topics::VEHICLE_REFLEX.name => {
            draw::<MotionCommand>(w, data)?
        }
        _ if t == topics::SONAR_RING.name => draw::<SonarRing>(w, data)?,
        _ if t == topics::ODOMETRY.name => draw::<Odometry>(w, data)?,
        _ if t == topics::VISION_DETECTIONS.name => draw::<Detections>(w, data)?,
        _ if t == topics::UMS_MAP.name => draw::<UncertaintyMap>(w, data)?,
        _ if t == topics::VISION_SIGHTINGS.name => draw::<LandmarkSighting>(w, data)?,
        _ if t == topics::UMS_EXPECTATIONS.name => draw::<Expectation>(w, data)?,
        _ if t == topics::EXECUTIVE_STATUS.name => draw::<MissionStatus>(w, data)?,
        _ if t == topics::EXECUTIVE_SERVO.name => draw::<ServoCorrection>(w, data)?,
        _ if t == topics::EXECUTIVE_POSE.name => draw::<harvey_msgs::PoseFix>(w, data)?,
        _ if t == topics::EXECUTIVE_PLAN.name => draw::<harvey_msgs::PlanSketch>(w, data)?,
        _ if t == topics::EXECUTIVE_BEHAVIOUR.name => draw::<harvey_msgs::BehaviourState>(w, data)?,
        _ if t == topics::VISION_REQUESTS.name => draw::<VisionRequest>(w, data)?,
        _ if t == topics::VISION_RESULTS.name => draw::<VisionResult>(w, data)?,
        _ if t == topics::ROSOUT.name => draw::<harvey_msgs::LogLine>(w, data)?,
        _ if t == topics::CAMERA_FRAME.name => {
            let (h, pixels) = decode_image(data)?;
            w.frame(&h, pixels)?;
        }
        _ => return Ok(false),
    }
    Ok(true)
}
