//! In process: a launch's services as nodes of this one process, one thread, on a hub of
//! in-memory topics. `harvey replay --in-process` (here): each tick the recorded inputs go out,
//! then each clock party takes its turn in the chain's order (the recorder's turn writes the new
//! recording), exactly as the multi-process replay hands the turns round over shared memory;
//! `harvey run --in-process` ([`run`]): the same with the simulated DRV and the bridge as the
//! clock master.

mod chain;
mod drv;
mod registry;
mod run;
mod sink;

use std::path::Path;
use std::rc::Rc;
use std::time::Instant;

use harvey_msgs::{EncodersRaw, LogLine, SonarRaw, TruePose, topics};
use harvey_recording::Recording;
use harvey_recording::ticks::{Input, for_each_tick};
use harvey_runtime::node::memory::{Hub, OwnedFrame, Sender};
use harvey_supervisor::LaunchFile;

use chain::Chain;
pub use run::run;

/// The recorded inputs' publishers (the replayer's ports).
struct Inputs {
    truth: Sender<TruePose>,
    sonar: Sender<SonarRaw>,
    encoders: Sender<EncodersRaw>,
    rosout: Sender<LogLine>,
    frames: Sender<Rc<OwnedFrame>>,
}

impl Inputs {
    fn open(hub: &Hub) -> anyhow::Result<Self> {
        Ok(Self {
            truth: hub.publisher(topics::SIM_TRUTH.name, topics::SIM_TRUTH.qos.buffer)?,
            sonar: hub.publisher(topics::DRV_SONAR_RAW.name, topics::DRV_SONAR_RAW.qos.buffer)?,
            encoders: hub.publisher(topics::DRV_ENCODERS_RAW.name, topics::DRV_ENCODERS_RAW.qos.buffer)?,
            rosout: hub.publisher(topics::ROSOUT.name, topics::ROSOUT.qos.buffer)?,
            frames: hub.publisher(topics::CAMERA_FRAME.name, topics::CAMERA_FRAME.qos.buffer)?,
        })
    }

    fn send(&self, inputs: &[Input<'_>]) -> anyhow::Result<()> {
        for input in inputs {
            match input {
                Input::Truth(m) => self.truth.send(*m),
                Input::Sonar(m) => self.sonar.send(*m),
                Input::Encoders(m) => self.encoders.send(*m),
                Input::Log(m) => self.rosout.send(**m),
                Input::Frame { header, pixels } => {
                    anyhow::ensure!(
                        pixels.len() == header.payload_len(),
                        "frame {} at {} ns: {} bytes of pixels for a {}x{} image",
                        header.seq,
                        header.stamp_ns,
                        pixels.len(),
                        header.width_px,
                        header.height_px
                    );
                    self.frames.send(Rc::new(OwnedFrame { header: *header, pixels: pixels.to_vec() }))
                }
            }
        }
        Ok(())
    }
}

/// Each clock party's share of the wall time, as printed: `name N ms, ...`.
pub fn turns_line(turns: &[(String, f64)]) -> String {
    let turns: Vec<String> = turns.iter().map(|(p, s)| format!("{p} {:.1} ms", s * 1e3)).collect();
    format!("turns: {}", turns.join(", "))
}

/// What a replay in process did.
pub struct Replayed {
    pub ticks: u64,
    pub messages: u64,
    pub sim_s: f64,
    pub wall_s: f64,
    /// Messages stamped after the tick their recorder's turn took them in, left out (as the
    /// recorder leaves them out).
    pub left_out: u64,
    /// Wall time each clock party's turns took, in the chain's order (the replayer's: reading
    /// nothing, handing the decoded inputs out; the recording is read between the turns).
    pub turns: Vec<(String, f64)>,
}

/// Replays `recording` with the services of the replay launch file `launch_path` (as
/// `replay_launch::prepare` writes it) in this process; the recorder's arguments say where
/// the new recording goes.
pub fn replay(recording: &Path, launch_path: &Path, run_dir: &Path) -> anyhow::Result<Replayed> {
    let launch = LaunchFile::load(launch_path)?;
    let vars = harvey_supervisor::variables(&launch, run_dir, "in-process")?;
    let hub = Hub::default();
    let inputs = Inputs::open(&hub)?;
    let (mut chain, _replayer) = Chain::open(&launch, &vars, &hub, &["harvey-replayer"])?;
    // As the replayer does: the whole recording is checked before any service sees it.
    let rec = Recording::open(recording)?;
    let contents = for_each_tick::<anyhow::Error>(&rec, |_, _| Ok(()))?;
    anyhow::ensure!(contents.ticks > 0, "{}: holds no inputs to replay", recording.display());
    chain.begin()?;

    let started = Instant::now();
    let ran = for_each_tick::<anyhow::Error>(&rec, |tick, ins| {
        let turn = Instant::now();
        inputs.send(ins)?;
        chain.master_spent(turn.elapsed().as_secs_f64());
        chain.turns(tick)
    });
    if let Err(e) = ran {
        // The writer's own error, if it stopped first, says more than a closed channel.
        return Err(chain.into_sink().finish().err().unwrap_or(e).context(recording.display().to_string()));
    }
    chain.stop()?;
    let turns = chain.turn_times();
    let sink = chain.into_sink();
    let (messages, left_out) = (sink.messages, sink.left_out);
    sink.finish()?;
    // The file finished is part of the replay's time (its writer runs beside the turns).
    let wall_s = started.elapsed().as_secs_f64();
    let sim_s = (contents.last_ns - contents.first_ns) as f64 / 1e9;
    Ok(Replayed { ticks: contents.ticks, messages, sim_s, wall_s, left_out, turns })
}
