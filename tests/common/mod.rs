//! Helpers shared by the multi-process tests: where the built binaries are, a bus prefix and a
//! scratch folder unique to each test, and checks that nothing is left behind.
#![allow(dead_code)]

pub mod docked;
pub mod sweeps;
pub mod truth;

use std::path::{Path, PathBuf};
use std::process::{Child, Command};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// The folder holding the workspace's binaries (the test runs from `<target>/<profile>/deps`).
pub fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.parent().and_then(Path::parent).expect("target folder").to_owned()
}

pub fn bin(name: &str) -> PathBuf {
    let p = bin_dir().join(name);
    assert!(p.is_file(), "{} is not built: run `cargo build --release --workspace` first", p.display());
    p
}

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A bus prefix no other test or run uses, so tests run in parallel and a killed test's
/// leftovers never meet the next run.
pub fn unique_prefix(tag: &str) -> String {
    static N: AtomicU32 = AtomicU32::new(0);
    format!("t{}{}{}_", tag, std::process::id(), N.fetch_add(1, Ordering::Relaxed))
}

/// A fresh scratch folder under the target directory, removed when the test passes and kept
/// (and named) when it fails: the runs' recordings are hundreds of MB, and CI's disk is finite.
/// (A sweep one seed at a time, `sweeps::sweep`, removes each seed's once read: a check made
/// over all the runs afterwards keeps none; sweep the failing seed again to look at it.)
pub fn scratch(tag: &str) -> Scratch {
    let d = bin_dir().join("test-scratch").join(format!("{tag}-{}", unique_prefix("")));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch folder");
    Scratch(d)
}

/// A copy of the shipped hallway mission `mission` (seed 1) at `seed`, in a scratch folder of
/// its own (kept while the returned [`Scratch`] lives), its world's path made absolute.
#[allow(dead_code, reason = "not every test runs another seed")]
pub fn at_seed(mission: &Path, seed: u64, tag: &str) -> (Scratch, PathBuf) {
    let world = repo().join("worlds/hallway.toml");
    let text = std::fs::read_to_string(mission)
        .expect("the mission")
        .replace("seed = 1", &format!("seed = {seed}"))
        .replace("../worlds/hallway.toml", world.to_str().expect("utf8"));
    let dir = scratch(tag);
    let file = dir.join(format!("seed{seed}.toml"));
    std::fs::write(&file, text).expect("written");
    (dir, file)
}

/// A scratch folder; see [`scratch`].
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept for a look: {}", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// A TCP port on loopback that was free a moment ago (network tests use loopback only).
#[allow(dead_code)] // not every test binary uses the network
pub fn free_port() -> u16 {
    let l = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    l.local_addr().expect("addr").port()
}

/// Shared-memory objects of a bus prefix still in /dev/shm.
pub fn shm_leftovers(prefix: &str) -> Vec<String> {
    std::fs::read_dir("/dev/shm")
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with(prefix))
                .collect()
        })
        .unwrap_or_default()
}

/// Processes whose environment carries this bus prefix (children that outlived the test).
pub fn processes_with_prefix(prefix: &str) -> Vec<u32> {
    let needle = format!("{}={prefix}", harvey_bus::PREFIX_ENV);
    std::fs::read_dir("/proc")
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|pid| {
            std::fs::read(format!("/proc/{pid}/environ"))
                .map(|env| env.split(|&b| b == 0).any(|kv| kv == needle.as_bytes()))
                .unwrap_or(false)
        })
        .filter(|pid| {
            // Zombies are not running; they only wait to be reaped.
            std::fs::read_to_string(format!("/proc/{pid}/stat")).map(|s| !s.contains(") Z ")).unwrap_or(false)
        })
        .collect()
}

/// Waits for a child to exit, up to `timeout`; kills it and fails the test if it does not.
pub fn wait_exit(child: &mut Child, timeout: Duration) -> std::process::ExitStatus {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(s) = child.try_wait().expect("try_wait") {
            return s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("process {} did not exit within {timeout:?}", child.id());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

pub fn signal(child: &Child, sig: i32) {
    // SAFETY: plain kill(2) on our own child.
    unsafe { libc::kill(child.id() as i32, sig) };
}

/// `harvey` with the given arguments, run from the repository root.
pub fn harvey(args: &[&str]) -> Command {
    let mut c = Command::new(bin("harvey"));
    c.args(args).current_dir(repo());
    c
}

/// A mission run by `harvey run` under its own bus prefix and run folder.
#[allow(dead_code)] // not every test binary runs missions
pub struct MissionRun {
    pub status: std::process::ExitStatus,
    pub stdout: String,
    pub stderr: String,
    /// The recording's bytes.
    pub mcap: Vec<u8>,
    /// The run folder: removed when the test passes, kept (and named) when it fails.
    pub dir: Scratch,
}

/// Runs `mission` (a path from the repository root, or absolute) in one process (`harvey run
/// --in-process`: the recording the processes make, `tests/in_process_run.rs`); checks nothing
/// of the mission.
#[allow(dead_code)]
pub fn run_mission(mission: &str, tag: &str) -> MissionRun {
    run_mission_with(mission, tag, &["--in-process"])
}

/// Runs `mission` under the supervisor, as processes; checks nothing of the mission, only that
/// its shared memory is gone afterwards.
#[allow(dead_code)]
pub fn run_mission_processes(mission: &str, tag: &str) -> MissionRun {
    run_mission_with(mission, tag, &[])
}

fn run_mission_with(mission: &str, tag: &str, how: &[&str]) -> MissionRun {
    let (prefix, dir) = (unique_prefix(tag), scratch(tag));
    let out = harvey(&["run", mission, "--prefix", &prefix, "--run-dir", dir.to_str().expect("utf8")])
        .args(how)
        .output()
        .expect("runs");
    assert_eq!(shm_leftovers(&prefix), Vec::<String>::new());
    MissionRun {
        status: out.status,
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        mcap: std::fs::read(dir.join("run.mcap")).unwrap_or_default(),
        dir,
    }
}

/// Runs `mission` at `seed` under a sensor condition (`conditions/NAME.toml`), as `harvey sweep
/// --in-process` does: the run's recording and its `harvey run` output (as stdout; the sweep's own output as
/// stderr); the status is the sweep's (success when the run reached its goal).
#[allow(dead_code)]
pub fn run_mission_under(mission: &str, condition: &str, seed: u64, tag: &str) -> MissionRun {
    let (prefix, dir) = (unique_prefix(tag), scratch(tag));
    let seeds = seed.to_string();
    let args = ["sweep", mission, "--seeds", &seeds, "--conditions", condition];
    let out = harvey(&args)
        .args(["--jobs", "1", "--keep", "--in-process"])
        .args(["--out", dir.to_str().expect("utf8"), "--prefix", &prefix])
        .output()
        .expect("runs");
    let run = dir.join("runs").join(format!("{condition}-s{seed}"));
    MissionRun {
        status: out.status,
        stdout: std::fs::read_to_string(run.join("harvey-run.log")).unwrap_or_default(),
        stderr: String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr),
        mcap: std::fs::read(run.join("run.mcap")).unwrap_or_default(),
        dir,
    }
}

/// Whether the map holds a pose: inside its convex polygon (with `tol`) and its heading wedge.
pub fn holds(m: &harvey_msgs::UncertaintyMap, x: f64, y: f64, th: f64, tol: f64) -> bool {
    // A map of fewer than three vertices (the exact start) is held to its heading only: as a
    // point where the pose stands.
    let mut m = *m;
    if m.vertex_count < 3 {
        m.vertex_count = 1;
        m.vertices_m[0] = [x, y];
    }
    m.holds(&harvey_msgs::Pose2 { x_m: x, y_m: y, heading_rad: th }, tol)
}

/// `harvey replay --check` of `recording`, under its own bus prefix and scratch run folder.
#[allow(dead_code)]
pub fn replay_check(recording: &Path, tag: &str) -> (std::process::Output, String, Scratch) {
    replay_check_with(recording, tag, &[])
}

/// [`replay_check`] with more arguments (`--in-process`).
#[allow(dead_code)]
pub fn replay_check_with(
    recording: &Path,
    tag: &str,
    more: &[&str],
) -> (std::process::Output, String, Scratch) {
    let (prefix, dir) = (unique_prefix(tag), scratch(tag));
    let out = harvey(&[
        "replay",
        recording.to_str().expect("utf8"),
        "--check",
        "--prefix",
        &prefix,
        "--run-dir",
        dir.to_str().expect("utf8"),
    ])
    .args(more)
    .output()
    .expect("replay runs");
    (out, prefix, dir)
}

/// Runs `mission` in process to its goal and holds `harvey replay --check` of its recording (as
/// processes, or with `how` = `--in-process`) to every message of it.
#[allow(dead_code)]
pub fn assert_replays(mission: &str, tag: &str, how: &[&str]) {
    let out = run_mission(mission, tag);
    assert!(out.status.success() && out.stdout.contains("goal reached"), "{}", out.stdout);
    let (replay, _, dir) = replay_check_with(&out.dir.join("run.mcap"), tag, how);
    let said = String::from_utf8_lossy(&replay.stdout);
    assert_eq!(replay.status.code(), Some(0), "{said}\n{}", String::from_utf8_lossy(&replay.stderr));
    let summary = mcap::Summary::read(&out.mcap).expect("summary").expect("present");
    let count = summary.stats.expect("stats").message_count as usize;
    assert_eq!(agreed(&replay), Some(count), "{said}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// How many messages a `--check` or `harvey diff` found identical (its `identical: N` line).
#[allow(dead_code)]
pub fn agreed(out: &std::process::Output) -> Option<usize> {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().find(|l| l.starts_with("identical: "))?;
    line.split_whitespace().nth(1)?.parse().ok()
}
