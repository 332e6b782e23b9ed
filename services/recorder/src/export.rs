//! `harvey export`: an MCAP recording to a Rerun file, through the same drawing as the live
//! recorder, using the world file the recording carries as an attachment.

use std::path::Path;

use harvey_cdr::{Ros2Msg, decode, decode_image};
use harvey_msgs::{
    Detections, EncodersRaw, Expectation, LandmarkSighting, MissionStatus, MotionCommand, Odometry,
    ServoCorrection, SonarRaw, SonarRing, TruePose, UncertaintyMap, VisionRequest, VisionResult, topics,
};

use crate::draw::Draw;
use crate::rrd::RrdWriter;
use crate::{RecordError, WORLD_MEDIA_TYPE};

fn draw<T: Ros2Msg + Draw>(w: &mut RrdWriter, data: &[u8]) -> Result<(), String> {
    let msg: T = decode(data).map_err(|e| e.to_string())?;
    msg.draw(w).map_err(|e| e.to_string())
}

/// Draws one recorded message; topics Harvey does not know are skipped (`Ok(false)`).
pub fn draw_recorded(w: &mut RrdWriter, topic: &str, data: &[u8]) -> Result<bool, String> {
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
        _ if t == topics::CAMERA_FRAME.name => {
            let (h, pixels) = decode_image(data).map_err(|e| e.to_string())?;
            w.frame(&h, pixels).map_err(|e| e.to_string())?;
        }
        _ => return Ok(false),
    }
    Ok(true)
}

/// Converts `mcap` to `rrd`, calling `progress(done, total)` as messages go; returns how many
/// messages were drawn.
pub fn export(mcap: &Path, rrd: &Path, mut progress: impl FnMut(u64, u64)) -> Result<u64, RecordError> {
    let err = |detail: String| RecordError { file: mcap.to_owned(), detail };
    let bytes = std::fs::read(mcap).map_err(|e| err(e.to_string()))?;
    let summary = mcap::Summary::read(&bytes).ok().flatten();
    let total = summary.as_ref().and_then(|s| s.stats.as_ref()).map_or(0, |s| s.message_count);
    let world = summary.as_ref().and_then(|s| {
        s.attachment_indexes.iter().filter(|a| a.media_type == WORLD_MEDIA_TYPE).find_map(|a| {
            let att = mcap::read::attachment(&bytes, a).ok()?;
            let text = String::from_utf8(att.data.to_vec()).ok()?;
            harvey_world::load_str(&text, &att.name).ok()
        })
    });
    let mut w = RrdWriter::create(rrd, world.as_ref())?;
    let stream = mcap::MessageStream::new(&bytes).map_err(|e| err(format!("not an MCAP file: {e}")))?;
    let mut drawn = 0u64;
    for (i, m) in stream.enumerate() {
        let m = m.map_err(|e| err(format!("corrupt after {i} messages: {e}")))?;
        if draw_recorded(&mut w, &m.channel.topic, &m.data)
            .map_err(|e| err(format!("message {i} on {}: {e}", m.channel.topic)))?
        {
            drawn += 1;
        }
        if i % 256 == 0 {
            progress(i as u64, total);
        }
    }
    progress(total, total);
    w.finish()?;
    Ok(drawn)
}
