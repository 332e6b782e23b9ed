//! A recording's inputs, tick by tick: which recorded topics are the run's inputs, and how a
//! recording splits into ticks of them (what `harvey-replayer` feeds a replay).
//!
//! A run's inputs are what came from outside the software under test: the simulator's truth,
//! the DRV's raw reports, the camera's frames, and the bridge's own warnings on `rosout` (it is
//! replaced too, so its lines are replayed, not produced again). `harvey replay` runs every other service again
//! and this replayer, as clock master, hands them the recorded inputs one tick at a time, just as
//! the bridge did live. In deterministic mode every party saw each tick's inputs at its turn, so
//! the services publish again exactly what they published then.

use harvey_cdr::{CdrError, decode, decode_image};
use harvey_msgs::{EncodersRaw, FrameHeader, LogLine, SonarRaw, TruePose, topics};

use crate::{Message, Recording, RecordingError};

/// Topics whose recorded messages are replayed; everything else is produced again.
pub const INPUT_TOPICS: [&str; 4] = [
    topics::SIM_TRUTH.name,
    topics::DRV_SONAR_RAW.name,
    topics::DRV_ENCODERS_RAW.name,
    topics::CAMERA_FRAME.name,
];

/// Services that produced the inputs live, left out of a replay (by executable name).
pub const INPUT_SERVICES: [&str; 3] = ["harvey-sim-drv", "harvey-denning-bridge", "harvey-camera"];

/// The `rosout` names of those services that log there: their lines are inputs of a replay.
pub const INPUT_LOG_NAMES: [&str; 1] = ["denning-bridge"];

/// One recorded input, decoded.
#[derive(Debug, Clone, PartialEq)]
pub enum Input<'a> {
    Truth(TruePose),
    Sonar(SonarRaw),
    Encoders(EncodersRaw),
    Frame {
        header: FrameHeader,
        pixels: &'a [u8],
    },
    /// A replaced service's warning; `seq` restored from the MCAP `sequence`.
    Log(Box<LogLine>),
}

/// Whether a recorded message is an input: one of [`INPUT_TOPICS`], or a line on `rosout` of
/// a service the replay replaces.
fn is_input(topic: &str, data: &[u8]) -> Result<bool, CdrError> {
    let t = topic.trim_start_matches('/');
    if t == topics::ROSOUT.name {
        let line: LogLine = decode(data)?;
        return Ok(INPUT_LOG_NAMES.contains(&line.name()));
    }
    Ok(INPUT_TOPICS.contains(&t))
}

/// Decodes one recorded message if it is an input. The MCAP `sequence` carries a frame's
/// sequence number (the standard image message has none).
pub fn decode_input<'a>(topic: &str, sequence: u32, data: &'a [u8]) -> Result<Option<Input<'a>>, CdrError> {
    let t = topic.trim_start_matches('/');
    Ok(Some(match t {
        _ if t == topics::SIM_TRUTH.name => Input::Truth(decode(data)?),
        _ if t == topics::DRV_SONAR_RAW.name => Input::Sonar(decode(data)?),
        _ if t == topics::DRV_ENCODERS_RAW.name => Input::Encoders(decode(data)?),
        _ if t == topics::CAMERA_FRAME.name => {
            let (mut header, pixels) = decode_image(data)?;
            header.seq = u64::from(sequence);
            Input::Frame { header, pixels }
        }
        _ if t == topics::ROSOUT.name => {
            let mut line: LogLine = decode(data)?;
            if !INPUT_LOG_NAMES.contains(&line.name()) {
                return Ok(None);
            }
            line.header.seq = u64::from(sequence);
            Input::Log(Box::new(line))
        }
        _ => return Ok(None),
    }))
}

/// What a recording holds for replay.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Contents {
    pub ticks: u64,
    pub inputs: u64,
    pub first_ns: u64,
    pub last_ns: u64,
    /// The largest frame, to size the shared-memory frames.
    pub max_frame_bytes: usize,
}

/// Calls `f(stamp_ns, inputs)` for each tick of the recording in order: the input messages
/// stamped `stamp_ns`, in the order they were recorded. A corrupt recording is an error naming
/// the message where it broke; an error of `f` ends the walk and is returned.
pub fn for_each_tick<E: From<RecordingError>>(
    recording: &Recording,
    mut f: impl FnMut(u64, &[Input<'_>]) -> Result<(), E>,
) -> Result<Contents, E> {
    let mut c = Contents::default();
    let mut messages = Vec::new();
    let mut tick: Option<u64> = None;
    let mut flush = |stamp: u64, messages: &mut Vec<Message<'_>>, c: &mut Contents| -> Result<(), E> {
        let inputs = messages
            .iter()
            .filter_map(|m| {
                decode_input(m.topic(), m.sequence(), m.data()).map_err(|e| m.undecodable(e)).transpose()
            })
            .collect::<Result<Vec<_>, _>>()?;
        for i in &inputs {
            if let Input::Frame { pixels, .. } = i {
                c.max_frame_bytes = c.max_frame_bytes.max(pixels.len());
            }
        }
        c.ticks += 1;
        c.inputs += inputs.len() as u64;
        c.first_ns = if c.ticks == 1 { stamp } else { c.first_ns };
        c.last_ns = stamp;
        let result = f(stamp, &inputs);
        drop(inputs);
        messages.clear();
        result
    };
    for m in recording.messages()? {
        let m = m?;
        if !is_input(m.topic(), m.data()).map_err(|e| m.undecodable(e))? {
            continue;
        }
        if let Some(t) = tick
            && t != m.log_time()
        {
            if m.log_time() < t {
                let (file, index, topic) = (recording.path().to_owned(), m.index(), m.topic().to_owned());
                return Err(RecordingError::BackInTime { file, index, topic }.into());
            }
            flush(t, &mut messages, &mut c)?;
        }
        tick = Some(m.log_time());
        messages.push(m);
    }
    if let Some(t) = tick {
        flush(t, &mut messages, &mut c)?;
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recorder;
    use harvey_msgs::{Header, Odometry};

    /// A recording of truths and odometry at the given `(is_truth, seq, stamp)`s.
    fn recording(name: &str, messages: &[(bool, u64, u64)]) -> Recording {
        let dir = std::env::temp_dir().join(format!("harvey-ticks-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let path = dir.join("t.mcap");
        let mut r = Recorder::create(&path).expect("create");
        let (truth, odometry) = (r.channel::<TruePose>("sim/truth"), r.channel::<Odometry>("odometry"));
        let (truth, odometry) = (truth.expect("channel"), odometry.expect("channel"));
        for &(is_truth, seq, stamp) in messages {
            let header = Header::new(seq, stamp);
            if is_truth {
                r.record(truth, &TruePose { header, ..Default::default() }).expect("record");
            } else {
                r.record(odometry, &Odometry { header, ..Default::default() }).expect("record");
            }
        }
        r.finish().expect("finish");
        let recording = Recording::open(&path).expect("read");
        std::fs::remove_dir_all(&dir).ok();
        recording
    }

    #[test]
    fn inputs_split_into_ticks_by_stamp_and_other_topics_are_left_out() {
        let r = recording("ok", &[(true, 1, 1000), (false, 1, 1000), (true, 2, 1000), (true, 3, 2000)]);
        let mut seen = Vec::new();
        let c = for_each_tick::<RecordingError>(&r, |stamp, inputs| {
            let seqs: Vec<u64> = inputs
                .iter()
                .map(|i| match i {
                    Input::Truth(t) => t.header.seq,
                    _ => 0,
                })
                .collect();
            seen.push((stamp, seqs));
            Ok(())
        })
        .expect("reads");
        assert_eq!(seen, [(1000, vec![1, 2]), (2000, vec![3])]);
        assert_eq!((c.ticks, c.inputs, c.first_ns, c.last_ns, c.max_frame_bytes), (2, 3, 1000, 2000, 0));
    }

    #[test]
    fn the_bridge_s_rosout_lines_are_inputs_and_other_services_lines_are_not() {
        use harvey_msgs::{LogLevel, LogLine};
        let dir = std::env::temp_dir().join(format!("harvey-ticks-{}-rosout", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let path = dir.join("t.mcap");
        let mut r = Recorder::create(&path).expect("create");
        let truth = r.channel::<TruePose>("sim/truth").expect("channel");
        let rosout = r.channel::<LogLine>("rosout").expect("channel");
        let line =
            |seq, stamp, name| LogLine::new(Header::new(seq, stamp), LogLevel::Warn, name, "bad frame");
        r.record(truth, &TruePose { header: Header::new(1, 1000), ..Default::default() }).expect("record");
        r.record(rosout, &line(4, 1000, "denning-bridge")).expect("record");
        r.record(rosout, &line(0, 1000, "ums")).expect("record");
        // A line of another service at a stamp with no input does not make a tick of its own.
        r.record(rosout, &line(1, 1500, "ums")).expect("record");
        r.record(truth, &TruePose { header: Header::new(2, 2000), ..Default::default() }).expect("record");
        r.finish().expect("finish");
        let recording = Recording::open(&path).expect("read");
        let mut seen = Vec::new();
        let c = for_each_tick::<RecordingError>(&recording, |stamp, inputs| {
            for i in inputs {
                if let Input::Log(l) = i {
                    seen.push((stamp, l.name().to_owned(), l.header.seq));
                }
            }
            Ok(())
        })
        .expect("reads");
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(
            seen,
            [(1000, "denning-bridge".to_owned(), 4)],
            "its number restored from the MCAP sequence"
        );
        assert_eq!((c.ticks, c.inputs), (2, 3));
    }

    #[test]
    fn an_input_stamped_before_the_last_is_an_error_naming_it() {
        let r = recording("back", &[(true, 1, 2000), (false, 1, 2000), (true, 2, 1000)]);
        let e = for_each_tick::<RecordingError>(&r, |_, _| Ok(())).expect_err("back in time");
        assert!(e.to_string().ends_with("t.mcap: message 2 on /sim/truth goes back in time"), "{e}");
    }
}
