//! `harvey chaos MISSION --kills N`: the mission run under the supervisor while seeded random
//! SIGKILLs hit its services, from outside, as a crash would. A run without kills first gives
//! the reference; each killed run is then judged against it: did the mission reach its goal,
//! how long was each service gone (kill to its successor on the bus), is the recording
//! identical, or which messages are missing, how far the robot truly moved while the service
//! was gone, and is shared memory clean after the launch.
//! `chaos/report.rs` tabulates the figures.

mod report;

use std::fs::File;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use harvey_geometry::Rng;
use nix::sys::signal::{Signal, kill, killpg};
use nix::unistd::Pid;

use report::{Kill, Run};

#[derive(clap::Args)]
pub struct ChaosArgs {
    /// The launch file (default: missions/default.toml).
    pub mission: Option<PathBuf>,
    /// Kills in all, spread over runs of `--kills-per-run`.
    #[arg(long, default_value_t = 10)]
    pub kills: usize,
    #[arg(long, default_value_t = 1)]
    pub kills_per_run: usize,
    /// Seed of the kill times and victims.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Services to kill (default: every service the launch restarts, and `supervisor`).
    #[arg(long, value_delimiter = ',')]
    pub services: Vec<String>,
    /// Output folder: the runs, chaos.md and chaos.csv.
    #[arg(long, default_value = "target/chaos")]
    pub out: PathBuf,
    /// Bus prefix stem; each run adds its number.
    #[arg(long, default_value = "chaos")]
    pub prefix: String,
}

/// The kill target that is the launch's supervisor process (its keeper starts a new one).
const SUPERVISOR: &str = "supervisor";

/// How long a service may stay gone before the harness stops waiting for it.
const BACK_TIMEOUT: Duration = Duration::from_secs(30);
/// How long a launch may take in all.
const RUN_TIMEOUT: Duration = Duration::from_secs(600);
const POLL: Duration = Duration::from_millis(2);

pub fn run(args: &ChaosArgs) -> anyhow::Result<i32> {
    let mission = args.mission.clone().unwrap_or_else(|| PathBuf::from("missions/default.toml"));
    let launch = harvey_supervisor::LaunchFile::load(&mission)?;
    let restartable: Vec<String> = launch
        .services
        .iter()
        .filter(|s| s.restart != harvey_supervisor::Restart::Never)
        .map(|s| s.name().to_owned())
        .chain([SUPERVISOR.to_owned()])
        .collect();
    let targets = if args.services.is_empty() { restartable.clone() } else { args.services.clone() };
    for t in &targets {
        anyhow::ensure!(
            restartable.contains(t),
            "{}: `{t}` is not a service the launch restarts (it restarts {restartable:?}, `{SUPERVISOR}` included)",
            mission.display()
        );
    }
    anyhow::ensure!(!targets.is_empty() && args.kills_per_run > 0, "nothing to kill");
    std::fs::create_dir_all(&args.out)?;
    let exe = std::env::current_exe()?;

    eprintln!("chaos: reference run of {} (no kills)", mission.display());
    let reference =
        launch_once(&exe, &mission, &args.out.join("reference"), &format!("{}r_", args.prefix), &[])?;
    anyhow::ensure!(
        reference.exit_code == Some(0),
        "the reference run failed ({:?}): see {}",
        reference.exit_code,
        reference.dir.display()
    );
    // Kills land at simulated times (the ticks they hit do not depend on the machine's speed).
    let span_ns = report::last_truth_ns(&reference.dir.join("run.mcap"))?;
    let mut rng = Rng::new(args.seed);
    let mut runs = Vec::new();
    let n_runs = args.kills.div_ceil(args.kills_per_run);
    for i in 0..n_runs {
        let k = args.kills_per_run.min(args.kills - i * args.kills_per_run);
        // Kill times within the middle of the mission, in order; victims drawn from the targets.
        let mut plan: Vec<(u64, String)> = (0..k)
            .map(|_| {
                let at = (span_ns as f64 * (0.1 + 0.7 * rng.uniform())) as u64;
                let who = targets[(rng.next_u64() % targets.len() as u64) as usize].clone();
                (at, who)
            })
            .collect();
        plan.sort_by_key(|(at, _)| *at);
        let dir = args.out.join(format!("run-{i:03}"));
        let mut run = launch_once(&exe, &mission, &dir, &format!("{}{i}_", args.prefix), &plan)?;
        run.judge(&reference.dir.join("run.mcap"));
        eprintln!("chaos: {}", run.line());
        runs.push(run);
    }
    let table = report::table(&runs, &reference, &cpu_line());
    std::fs::write(args.out.join("chaos.md"), &table)?;
    std::fs::write(args.out.join("chaos.csv"), report::csv(&runs))?;
    print!("{table}");
    let all_good = runs.iter().all(|r| r.exit_code == Some(0));
    Ok(if all_good { 0 } else { 1 })
}

/// The machine the figures came from.
fn cpu_line() -> String {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model = info
        .lines()
        .find_map(|l| l.strip_prefix("model name"))
        .map_or("unknown CPU", |m| m.trim_start_matches([' ', '\t', ':']));
    format!("{model}, {} cores", std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Launches the mission once, killing as `plan` says (at simulated times, from `sim/truth`).
fn launch_once(
    exe: &Path,
    mission: &Path,
    dir: &Path,
    prefix: &str,
    plan: &[(u64, String)],
) -> anyhow::Result<Run> {
    if dir.exists() {
        std::fs::remove_dir_all(dir)?;
    }
    std::fs::create_dir_all(dir)?;
    let log = File::create(dir.join("launch.log"))?;
    let mut child = Command::new(exe)
        .arg("launch")
        .arg(mission)
        .args(["--run-dir", &dir.display().to_string(), "--prefix", prefix])
        .stdin(Stdio::null())
        .stdout(log.try_clone()?)
        .stderr(log)
        .process_group(0)
        .spawn()?;
    let group = Pid::from_raw(child.id() as i32);
    let started = Instant::now();
    let launch = harvey_supervisor::LaunchFile::load(mission)?;
    let names: Vec<String> = launch.services.iter().map(|s| s.name().to_owned()).collect();
    // Every service on the bus: the mission is under way.
    let up = loop {
        if child.try_wait()?.is_some() || started.elapsed() > RUN_TIMEOUT {
            break Instant::now();
        }
        let nodes = harvey_bus::live_nodes(prefix).unwrap_or_default();
        if names.iter().all(|n| nodes.iter().any(|x| x.alive && &x.name == n)) {
            break Instant::now();
        }
        std::thread::sleep(POLL);
    };
    let mut kills = Vec::new();
    if !plan.is_empty() {
        let bus = harvey_bus::Bus::join_with_prefix("harvey-chaos", prefix)?;
        let truth = bus.subscriber(harvey_msgs::topics::SIM_TRUTH)?;
        let mut now_ns = 0;
        let mut pose = None;
        for (at, who) in plan {
            let at_s = *at as f64 * 1e-9;
            while now_ns < *at && child.try_wait()?.is_none() && started.elapsed() < RUN_TIMEOUT {
                if let Some(t) = truth.latest()? {
                    now_ns = t.header.stamp_ns;
                    pose = Some(t.world_from_robot);
                }
                std::thread::sleep(POLL);
            }
            if child.try_wait()?.is_some() || now_ns < *at {
                kills.push(Kill { service: who.clone(), at_s, back_ms: None, moved_m: None, missed: true });
                continue;
            }
            kills.push(kill_one(prefix, who, at_s, &truth, &mut pose));
        }
    }
    let status = loop {
        if let Some(s) = child.try_wait()? {
            break Some(s);
        }
        if started.elapsed() > RUN_TIMEOUT {
            let _ = killpg(group, Signal::SIGKILL);
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let leftovers = shm_leftovers(prefix);
    Ok(Run::new(dir, status.and_then(|s| s.code()), up.elapsed(), kills, leftovers))
}

/// SIGKILLs `who` and waits for its successor on the bus (the supervisor's node is its clock
/// watch, `harvey-supervisor`); the robot's true travel meanwhile is read from `sim/truth`.
fn kill_one(
    prefix: &str,
    who: &str,
    at_s: f64,
    truth: &harvey_bus::Subscriber<harvey_msgs::TruePose>,
    pose: &mut Option<harvey_msgs::Pose2>,
) -> Kill {
    let node = if who == SUPERVISOR { "harvey-supervisor" } else { who };
    let find = || {
        harvey_bus::live_nodes(prefix)
            .unwrap_or_default()
            .into_iter()
            .find(|n| n.alive && n.name == node)
            .map(|n| n.pid)
    };
    let mut k = Kill { service: who.to_owned(), at_s, back_ms: None, moved_m: None, missed: true };
    let Some(pid) = find() else { return k };
    if let Some(t) = truth.latest().ok().flatten() {
        *pose = Some(t.world_from_robot);
    }
    if kill(Pid::from_raw(pid), Signal::SIGKILL).is_err() {
        return k;
    }
    let before = *pose;
    k.missed = false;
    let killed = Instant::now();
    while killed.elapsed() < BACK_TIMEOUT {
        if let Some(t) = truth.latest().ok().flatten() {
            *pose = Some(t.world_from_robot);
        }
        if find().is_some_and(|p| p != pid) {
            k.back_ms = Some(killed.elapsed().as_secs_f64() * 1e3);
            break;
        }
        std::thread::sleep(POLL);
    }
    if let (Some(a), Some(b)) = (before, *pose) {
        k.moved_m = Some((b.x_m - a.x_m).hypot(b.y_m - a.y_m));
    }
    k
}

/// Shared-memory files of a bus prefix still in /dev/shm.
fn shm_leftovers(prefix: &str) -> usize {
    std::fs::read_dir("/dev/shm")
        .map(|d| {
            d.filter_map(|e| e.ok()).filter(|e| e.file_name().to_string_lossy().starts_with(prefix)).count()
        })
        .unwrap_or(0)
}
