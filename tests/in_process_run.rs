//! `harvey run --in-process` against `harvey run`: the default mission, ptrans (plan-and-monitor)
//! and docking (acceptor-sequenced) run both ways record the same messages (`harvey diff`), the
//! in-process run as one process with no shared memory; launches it cannot run are refused.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::path::Path;
use std::process::Output;

fn text(out: &Output) -> String {
    format!("{}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

/// Runs `mission` under the supervisor (`in_process` false) or in process; its output and
/// run folder (its recording is `run.mcap` there).
fn run(mission: &str, tag: &str, in_process: bool) -> (Output, common::Scratch) {
    let (prefix, dir) = (common::unique_prefix(tag), common::scratch(tag));
    let mut args = vec!["run", mission, "--prefix", &prefix, "--run-dir", dir.to_str().expect("utf8")];
    if in_process {
        args.push("--in-process");
    }
    let out = common::harvey(&args).output().expect("runs");
    assert!(out.status.success(), "{mission} (in process: {in_process}): {}", text(&out));
    // In process nothing touches shared memory; under the supervisor everything is cleaned up.
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    (out, dir)
}

fn diff(a: &Path, b: &Path) -> Output {
    common::harvey(&["diff", a.to_str().expect("utf8"), b.to_str().expect("utf8")])
        .output()
        .expect("diff runs")
}

/// Runs `mission` both ways at once and checks the recordings agree, message for message; the
/// number of messages compared.
fn both_ways(mission: &str, tag: &str) -> usize {
    let ((processes, a), (in_process, b)) = std::thread::scope(|s| {
        let a = s.spawn(|| run(mission, &format!("{tag}-mp"), false));
        let b = s.spawn(|| run(mission, &format!("{tag}-ip"), true));
        (a.join().expect("multi-process run"), b.join().expect("in-process run"))
    });
    let same = diff(&a.join("run.mcap"), &b.join("run.mcap"));
    assert_eq!(same.status.code(), Some(0), "{mission}: {}", text(&same));
    // Both print the same mission summary; the in-process run says how fast it went.
    let summary = |o: &Output| {
        let out = String::from_utf8_lossy(&o.stdout).into_owned();
        out.lines()
            .filter(|l| l.starts_with("mission:") || l.starts_with("launch:"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert!(!summary(&processes).is_empty(), "{}", text(&processes));
    assert_eq!(summary(&processes), summary(&in_process));
    let stdout = String::from_utf8_lossy(&in_process.stdout);
    assert!(stdout.contains("in process: ") && stdout.contains("x real time"), "{stdout}");
    common::agreed(&same).unwrap_or_else(|| panic!("no count of identical messages: {}", text(&same)))
}

#[test]
fn the_default_mission_in_process_records_what_its_processes_record() {
    let n = both_ways("missions/default.toml", "iprun-default");
    assert!(n > 6000, "only {n} messages compared");
}

#[test]
fn ptrans_in_process_records_what_its_processes_record() {
    let n = both_ways("missions/ptrans.toml", "iprun-ptrans");
    assert!(n > 1000, "only {n} messages compared");
}

#[test]
fn docking_in_process_records_what_its_processes_record() {
    let n = both_ways("missions/docking.toml", "iprun-docking");
    assert!(n > 1000, "only {n} messages compared");
}

#[test]
fn launches_that_cannot_run_in_process_are_refused_with_the_reason() {
    let dir = common::scratch("iprun-bad");
    let default = std::fs::read_to_string(common::repo().join("missions/default.toml")).expect("default");
    let world = common::repo().join("worlds/hallway.toml");
    let default = default.replace("../worlds/hallway.toml", world.to_str().expect("utf8"));
    let refused = |name: &str, text_of: String| {
        let file = dir.join(name);
        std::fs::write(&file, text_of).expect("written");
        let out = common::harvey(&["run", "--in-process", file.to_str().expect("utf8")])
            .args(["--run-dir", dir.join("run").to_str().expect("utf8")])
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(2), "{}", text(&out));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    // Paced by the wall clock: no chain to run in one thread.
    let realtime = refused("realtime.toml", default.replace("clock = \"lockstep\"", "clock = \"realtime\""));
    assert!(realtime.contains("only a deterministic launch"), "{realtime}");
    // A real DRV's serial line instead of the simulator.
    let (from, to) = (
        default.find("[[service]]\nname = \"sim-drv\"").expect("sim-drv"),
        default.find("[[service]]\nname = \"denning-bridge\"").expect("bridge"),
    );
    let real = format!("{}{}", &default[..from], &default[to..]);
    let no_sim = refused("real-drv.toml", real);
    assert!(no_sim.contains("no harvey-sim-drv"), "{no_sim}");
    // A service with no node for in-process runs, named with those that have one.
    let foreign = default.replace("name = \"ums\"", "name = \"ums\"\nbinary = \"harvey-foxglove-bridge\"");
    let unknown = refused("foreign.toml", foreign);
    assert!(unknown.contains("service ums (harvey-foxglove-bridge) has no node registered"), "{unknown}");
    assert!(unknown.contains("harvey-camera"), "{unknown}");
    // The live viewers need the processes' bus.
    let out = common::harvey(&["run", "--in-process", "--realtime"]).output().expect("runs");
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot be used with"), "{}", text(&out));
    let _ = std::fs::remove_dir_all(dir);
}
