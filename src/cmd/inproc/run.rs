//! `harvey run --in-process`: a deterministic launch's services as one process, one thread,
//! with no shared memory: the simulated DRV and the bridge on an in-memory line, the other
//! services as nodes on a hub, the recorder's turn writing the recording. Each tick goes as the
//! bus runs it: the bridge's `SY`, the DRV's tick, its reports on the topics, then each party's
//! turn in the clock chain's order; the launch ends when its `end_with` service has finished.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use harvey_runtime::node::memory::Hub;
use harvey_supervisor::{LaunchFile, Outcome};

use super::chain::{Chain, Own};
use super::drv::{Drv, bridge_state};

/// The executables the in-process run drives itself: the DRV's line, not nodes.
const SIM: &str = "harvey-sim-drv";
const BRIDGE: &str = "harvey-denning-bridge";

/// What an in-process run did.
pub struct Ran {
    pub outcome: Outcome,
    pub ticks: u64,
    pub sim_s: f64,
    pub wall_s: f64,
    /// Wall time each clock party's turns took, in the chain's order (the bridge's: the line's
    /// round, the simulator's tick included).
    pub turns: Vec<(String, f64)>,
}

/// Runs launch file `launch_path` in this process, its files in `run_dir`.
pub fn run(launch_path: &Path, run_dir: &Path) -> anyhow::Result<Ran> {
    let launch = LaunchFile::load(launch_path)?;
    let path = launch_path.display();
    anyhow::ensure!(
        !launch.clock_chain().is_empty(),
        "{path}: only a deterministic launch (`clock = \"lockstep\"` with a `clock_master`) runs in process"
    );
    let end_with = launch.settings.end_with.as_ref().map(|s| s.get_ref().clone());
    let end_with = end_with.ok_or_else(|| anyhow::anyhow!("{path}: no `end_with` service"))?;
    std::fs::create_dir_all(run_dir)?;
    let vars = harvey_supervisor::variables(&launch, run_dir, "in-process")?;
    let hub = Hub::default();
    let (mut chain, own) = Chain::open(&launch, &vars, &hub, &[SIM, BRIDGE])?;
    let find = |binary: &str| -> anyhow::Result<&Own> {
        own.iter().find(|o| o.binary == binary).ok_or_else(|| {
            anyhow::anyhow!(
                "{path}: no {binary}: in process a run drives the simulated DRV through the bridge \
                 (a real DRV's line runs under the supervisor: `harvey run` without --in-process)"
            )
        })
    };
    let (sim, bridge) = (find(SIM)?, find(BRIDGE)?);
    let mut state = bridge_state(bridge)?;
    let mut drv = Drv::open(sim, bridge, &mut state, &hub)?;
    chain.begin()?;

    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&stop))?;
    }
    let wall_limit = Duration::from_secs(launch.settings.wall_limit_s);
    let started = Instant::now();
    let (mut tick, mut ticks) = (0, 0);
    let mut turn = || -> anyhow::Result<Option<Outcome>> {
        if stop.load(Ordering::Relaxed) {
            return Ok(Some(Outcome::Interrupted));
        }
        if started.elapsed() > wall_limit {
            return Ok(Some(Outcome::WallLimit { limit_s: launch.settings.wall_limit_s }));
        }
        let round = Instant::now();
        let next = drv.round(tick)?;
        let next = next.ok_or_else(|| anyhow::anyhow!("the simulated DRV closed no tick after {tick} ns"))?;
        chain.master_spent(round.elapsed().as_secs_f64());
        chain.turns(next)?;
        (tick, ticks) = (next, ticks + 1);
        // As under the supervisor: the launch is over once the `end_with` service has finished
        // (its exit code is the outcome's).
        Ok(chain.finished(&end_with).then(|| Outcome::Ended { service: end_with.clone(), code: 0 }))
    };
    let ended = loop {
        match turn() {
            Ok(None) => {}
            Ok(Some(outcome)) => break Ok(outcome),
            Err(e) => break Err(e),
        }
    };
    let ended = ended.and_then(|outcome| {
        let codes = chain.stop()?;
        Ok(match outcome {
            Outcome::Ended { service, .. } => {
                let code = codes.iter().find(|(n, _)| *n == service).map_or(0, |(_, c)| i32::from(*c));
                Outcome::Ended { service, code }
            }
            other => other,
        })
    });
    let turns = chain.turn_times();
    // The recording is finished whatever ended the run, so that a failed run keeps its file.
    let finished = chain.into_sink().finish();
    let outcome = match (ended, finished) {
        (Ok(o), Ok(())) => o,
        (Err(e), _) => return Err(e.context(format!("{path}, in process"))),
        (Ok(_), Err(e)) => return Err(e.context(format!("{path}: finishing the recording"))),
    };
    let wall_s = started.elapsed().as_secs_f64();
    Ok(Ran { outcome, ticks, sim_s: tick as f64 / 1e9, wall_s, turns })
}
