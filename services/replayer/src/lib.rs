//! The replayer's logic: which recorded topics are the run's inputs, and how a recording splits
//! into ticks of them.
//!
//! A run's inputs are what came from outside the software under test: the simulator's truth,
//! the DRV's raw reports and the camera's frames. `harvey replay` runs every other service again
//! and this replayer, as clock master, hands them the recorded inputs one tick at a time, just as
//! the bridge did live. In deterministic mode every party saw each tick's inputs at its turn, so
//! the services publish again exactly what they published then.

use harvey_cdr::{decode, decode_image};
use harvey_msgs::{EncodersRaw, FrameHeader, SonarRaw, TruePose, topics};

/// Topics whose recorded messages are replayed; everything else is produced again.
pub const INPUT_TOPICS: [&str; 4] = [
    topics::SIM_TRUTH.name,
    topics::DRV_SONAR_RAW.name,
    topics::DRV_ENCODERS_RAW.name,
    topics::CAMERA_FRAME.name,
];

/// Services that produced the inputs live, left out of a replay (by executable name).
pub const INPUT_SERVICES: [&str; 3] = ["harvey-sim-drv", "harvey-denning-bridge", "harvey-camera"];

/// One recorded input, decoded.
#[derive(Debug, Clone, PartialEq)]
pub enum Input<'a> {
    Truth(TruePose),
    Sonar(SonarRaw),
    Encoders(EncodersRaw),
    Frame { header: FrameHeader, pixels: &'a [u8] },
}

/// Decodes one recorded message if it is an input. The MCAP `sequence` carries a frame's
/// sequence number (the standard image message has none).
pub fn decode_input<'a>(topic: &str, sequence: u32, data: &'a [u8]) -> anyhow::Result<Option<Input<'a>>> {
    let t = topic.trim_start_matches('/');
    let bad = |e: harvey_cdr::CdrError| anyhow::anyhow!("`{t}`: {e}");
    Ok(Some(match t {
        _ if t == topics::SIM_TRUTH.name => Input::Truth(decode(data).map_err(bad)?),
        _ if t == topics::DRV_SONAR_RAW.name => Input::Sonar(decode(data).map_err(bad)?),
        _ if t == topics::DRV_ENCODERS_RAW.name => Input::Encoders(decode(data).map_err(bad)?),
        _ if t == topics::CAMERA_FRAME.name => {
            let (mut header, pixels) = decode_image(data).map_err(bad)?;
            header.seq = u64::from(sequence);
            Input::Frame { header, pixels }
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
/// the message where it broke.
pub fn for_each_tick(
    bytes: &[u8],
    mut f: impl FnMut(u64, &[Input<'_>]) -> anyhow::Result<()>,
) -> anyhow::Result<Contents> {
    let stream = mcap::MessageStream::new(bytes).map_err(|e| anyhow::anyhow!("not an MCAP file: {e}"))?;
    let mut c = Contents::default();
    let mut messages = Vec::new();
    let mut tick: Option<u64> = None;
    let mut flush = |stamp: u64, messages: &mut Vec<mcap::Message<'_>>, c: &mut Contents| {
        let inputs = messages
            .iter()
            .filter_map(|m| decode_input(&m.channel.topic, m.sequence, &m.data).transpose())
            .collect::<anyhow::Result<Vec<_>>>()?;
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
    for (i, m) in stream.enumerate() {
        let m = m.map_err(|e| anyhow::anyhow!("corrupt after {i} messages: {e}"))?;
        if !INPUT_TOPICS.contains(&m.channel.topic.trim_start_matches('/')) {
            continue;
        }
        if let Some(t) = tick
            && t != m.log_time
        {
            anyhow::ensure!(m.log_time > t, "message {i} on {} goes back in time", m.channel.topic);
            flush(t, &mut messages, &mut c)?;
        }
        tick = Some(m.log_time);
        messages.push(m);
    }
    if let Some(t) = tick {
        flush(t, &mut messages, &mut c)?;
    }
    Ok(c)
}
