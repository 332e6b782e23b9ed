//! `harvey export`: an MCAP recording to a Rerun file, through the same drawing as the live
//! recorder, using the world file the recording carries as an attachment.

use std::path::Path;

use harvey_cdr::{Ros2Msg, decode, decode_image};
use harvey_msgs::{
    Detections, EncodersRaw, Expectation, LandmarkSighting, MissionStatus, MotionCommand, Odometry,
    ServoCorrection, SonarRaw, SonarRing, TruePose, UncertaintyMap, VisionRequest, VisionResult, topics,
};

use harvey_world::{Pole, World};

use crate::draw::Draw;
use crate::rrd::RrdWriter;
use crate::{RecordError, WORLD_MEDIA_TYPE, WORLD_METADATA};

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
    // The messages are the recording; a world that no longer loads (an older file format, say)
    // only costs the drawing of the walls.
    let world = match summary.as_ref().map(|s| recorded_world(&bytes, s)) {
        Some(Ok(world)) => world.map(|(w, _)| w),
        Some(Err(e)) => {
            tracing::warn!("{}: {e}; drawing without the world", mcap.display());
            None
        }
        None => None,
    };
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

/// The world a recording carries, with its `[poles]` placed by the recorded seed (1 when the
/// recording predates the `harvey.world` record, as the recorder's default), and those poles;
/// `None` without a world attachment. A world attachment that does not load is an error naming it.
pub fn recorded_world(bytes: &[u8], summary: &mcap::Summary) -> Result<Option<(World, Vec<Pole>)>, String> {
    let Some(index) = summary.attachment_indexes.iter().find(|a| a.media_type == WORLD_MEDIA_TYPE) else {
        return Ok(None);
    };
    let att = mcap::read::attachment(bytes, index)
        .map_err(|e| format!("world attachment `{}`: {e}", index.name))?;
    let text = std::str::from_utf8(&att.data).map_err(|e| format!("world attachment `{}`: {e}", att.name))?;
    let mut world = harvey_world::load_str(text, &att.name).map_err(|e| format!("world attachment: {e}"))?;
    let mut seed = 1;
    if let Some(m) = summary.metadata_indexes.iter().find(|m| m.name == WORLD_METADATA) {
        let record =
            mcap::read::metadata(bytes, m).map_err(|e| format!("`{WORLD_METADATA}` metadata: {e}"))?;
        if let Some(text) = record.metadata.get("seed") {
            seed = text.parse().map_err(|e| format!("`{WORLD_METADATA}` metadata: seed `{text}`: {e}"))?;
        }
    }
    let poles = world.place_poles(seed).map_err(|e| format!("world attachment `{}`: {e}", att.name))?;
    Ok(Some((world, poles)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recorder;

    const ARENA: &str = include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../../worlds/arena.toml"));

    fn recording(name: &str, world: &str, seed: u64) -> Vec<u8> {
        let dir = std::env::temp_dir().join(format!("harvey-export-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let path = dir.join("t.mcap");
        let mut r = Recorder::create(&path).expect("create");
        r.attach_world("arena.toml", world, seed).expect("attach");
        r.finish().expect("finish");
        let bytes = std::fs::read(&path).expect("read");
        std::fs::remove_dir_all(&dir).ok();
        bytes
    }

    fn walls(w: &World) -> Vec<[[f64; 2]; 2]> {
        w.walls.iter().map(|w| [w.from, w.to]).collect()
    }

    #[test]
    fn export_places_the_poles_where_the_recorded_seed_put_them() {
        for seed in [3, 4] {
            let bytes = recording(&format!("s{seed}"), ARENA, seed);
            let summary = mcap::Summary::read(&bytes).expect("summary").expect("present");
            let (got, placed) = recorded_world(&bytes, &summary).expect("loads").expect("a world");
            let mut want = harvey_world::load_str(ARENA, "arena.toml").expect("arena");
            let bare = want.walls.len();
            let poles = want.place_poles(seed).expect("placed");
            assert_eq!((poles.len(), &placed), (10, &poles));
            assert!(want.walls.len() > bare, "poles are walls");
            assert_eq!(walls(&got), walls(&want), "seed {seed}");
        }
        let (a, b) = (recording("a", ARENA, 3), recording("b", ARENA, 4));
        let world = |bytes: &[u8]| {
            let s = mcap::Summary::read(bytes).expect("summary").expect("present");
            walls(&recorded_world(bytes, &s).expect("loads").expect("a world").0)
        };
        assert_ne!(world(&a), world(&b), "another seed, other places");
    }

    #[test]
    fn a_world_attachment_that_does_not_load_is_named() {
        let bytes = recording("bad", "[[wall]]\nfrom = \"here\"\n", 1);
        let summary = mcap::Summary::read(&bytes).expect("summary").expect("present");
        let e = recorded_world(&bytes, &summary).expect_err("malformed world");
        assert!(e.contains("world attachment") && e.contains("arena.toml"), "{e}");
    }
}
