//! Running a sweep's runs: each a `harvey run` child process (the same binary) in its own process
//! group with its own bus prefix, at most `jobs` at once. Ctrl-C (or SIGTERM) stops them: each
//! running child's group gets SIGTERM (the supervisor stops its services), and SIGKILL if it
//! has not ended after a grace period.

use std::fs::File;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, killpg};
use nix::unistd::Pid;

/// How long a stopped run may take to stop its services before it is killed.
const STOP_GRACE: Duration = Duration::from_secs(20);
const POLL: Duration = Duration::from_millis(50);

/// One run to make.
#[derive(Debug, Clone)]
pub struct Job {
    /// Index into the sweep's conditions.
    pub condition: usize,
    pub seed: u64,
    /// The launch file copy to run (written before, removed after).
    pub launch: PathBuf,
    pub launch_text: String,
    pub run_dir: PathBuf,
    pub prefix: String,
    /// Run it in one process (`harvey run --in-process`).
    pub in_process: bool,
}

/// A run that ended by itself.
#[derive(Debug)]
pub struct Done {
    pub job: Job,
    /// `None` when a signal ended it.
    pub exit_code: Option<i32>,
    pub wall_s: f64,
    pub log: PathBuf,
}

/// How the runs ended: all of them, or interrupted (those still running are in `stopped`).
#[derive(Debug, Default)]
pub struct Ending {
    pub interrupted: bool,
    pub stopped: Vec<Job>,
    /// Why no more runs were started for lack of disk (`disk.rs`), and how many were not.
    pub short_of_disk: Option<String>,
    pub not_started: usize,
}

/// SIGINT and SIGTERM, noticed: set once either arrives.
pub fn interrupt_flag() -> std::io::Result<Arc<AtomicBool>> {
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&flag))?;
    }
    Ok(flag)
}

struct Running {
    job: Job,
    child: Child,
    started: Instant,
    log: PathBuf,
}

/// Starts `job` as `exe run LAUNCH --run-dir D --prefix P [--in-process]`, its output in
/// `D/harvey-run.log`.
fn start(exe: &Path, job: Job) -> anyhow::Result<Running> {
    if job.run_dir.exists() {
        std::fs::remove_dir_all(&job.run_dir)?;
    }
    std::fs::create_dir_all(&job.run_dir)?;
    std::fs::write(&job.launch, &job.launch_text)?;
    let log = job.run_dir.join("harvey-run.log");
    let out = File::create(&log)?;
    let child = Command::new(exe)
        .arg("run")
        .arg(&job.launch)
        .arg("--run-dir")
        .arg(&job.run_dir)
        .arg("--prefix")
        .arg(&job.prefix)
        .args(job.in_process.then_some("--in-process"))
        .stdin(Stdio::null())
        .stdout(out.try_clone()?)
        .stderr(out)
        .process_group(0)
        .spawn()?;
    Ok(Running { job, child, started: Instant::now(), log })
}

/// Runs `jobs`, at most `max` at once, calling `done` as each ends; stops on `interrupt`, and
/// starts no more once `out`'s disk lacks room for another run (those running finish).
pub fn run_all(
    exe: &Path,
    jobs: Vec<Job>,
    max: usize,
    out: &Path,
    interrupt: &AtomicBool,
    mut done: impl FnMut(Done) -> anyhow::Result<()>,
) -> anyhow::Result<Ending> {
    let mut queue = jobs.into_iter();
    let mut running: Vec<Running> = Vec::new();
    let (mut reserve, mut short_of_disk) = (super::disk::Reserve::default(), None);
    loop {
        if interrupt.load(Ordering::Relaxed) {
            return Ok(Ending { interrupted: true, stopped: stop_all(running), ..Ending::default() });
        }
        while running.len() < max.max(1) && short_of_disk.is_none() {
            short_of_disk = reserve.short(out, super::disk::free_bytes(out)?);
            if short_of_disk.is_some() {
                break;
            }
            let Some(job) = queue.next() else { break };
            match start(exe, job) {
                Ok(r) => running.push(r),
                Err(e) => {
                    stop_all(running);
                    return Err(e);
                }
            }
        }
        if running.is_empty() {
            let not_started = queue.count();
            return Ok(Ending {
                short_of_disk: short_of_disk.filter(|_| not_started > 0),
                not_started,
                ..Ending::default()
            });
        }
        let mut i = 0;
        while i < running.len() {
            match running[i].child.try_wait() {
                Err(e) => {
                    stop_all(running);
                    return Err(e.into());
                }
                Ok(None) => i += 1,
                Ok(Some(status)) => {
                    let r = running.swap_remove(i);
                    let _ = std::fs::remove_file(&r.job.launch);
                    let wall_s = r.started.elapsed().as_secs_f64();
                    let run_dir = r.job.run_dir.clone();
                    if let Err(e) = done(Done { job: r.job, exit_code: status.code(), wall_s, log: r.log }) {
                        stop_all(running);
                        return Err(e);
                    }
                    // What `done` left of the run (a failed run's recording).
                    reserve.kept(&run_dir);
                }
            }
        }
        std::thread::sleep(POLL);
    }
}

/// SIGTERM to each run's process group, SIGKILL after [`STOP_GRACE`]; returns their jobs.
fn stop_all(mut running: Vec<Running>) -> Vec<Job> {
    let group = |r: &Running| i32::try_from(r.child.id()).ok().map(Pid::from_raw);
    for r in &running {
        if let Some(pg) = group(r) {
            let _ = killpg(pg, Signal::SIGTERM);
        }
    }
    let deadline = Instant::now() + STOP_GRACE;
    while running.iter_mut().any(|r| matches!(r.child.try_wait(), Ok(None))) && Instant::now() < deadline {
        std::thread::sleep(POLL);
    }
    for r in &mut running {
        if matches!(r.child.try_wait(), Ok(None)) {
            if let Some(pg) = group(r) {
                let _ = killpg(pg, Signal::SIGKILL);
            }
            let _ = r.child.wait();
        }
        let _ = std::fs::remove_file(&r.job.launch);
    }
    running.into_iter().map(|r| r.job).collect()
}
