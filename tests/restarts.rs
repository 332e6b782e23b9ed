//! Services killed with SIGKILL in the middle of the default mission (deterministic), through
//! `harvey chaos`, each run judged against a run without kills (issue 20): the simulated DRV
//! and the bridge come back as the same robot and the same line; the encoders, the sonar, the
//! camera, the vision workers and the UMS resume their checkpointed state, the executive runs its
//! journal of inputs again, and each finds the inputs of the tick it missed (every process
//! re-offers first): in each case the recording is identical to the run without kills.
//! A restarted recorder continues its recording, losing at most half a second. On the code
//! before, the bridge's and the DRV's restarts hung the chain, the encoders' ended the mission
//! 1.8 m from where it should, the others' recordings differed, and the recorder's truncated
//! its file; a killed supervisor took every service down with it.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::path::Path;

/// One row of `chaos.csv`.
#[derive(Debug)]
struct Row {
    service: String,
    back_ms: Option<f64>,
    exit_code: Option<i32>,
    identical: bool,
    missing: usize,
    missing_span_s: f64,
    extra: usize,
    end_apart_m: f64,
    shm_left: usize,
    missed: bool,
    /// The robot's true travel between the kill and the successor's arrival.
    moved_m: Option<f64>,
}

fn chaos(tag: &str, services: &str, kills: usize, seed: u64) -> (Vec<Row>, String) {
    let (rows, log, _) = chaos_in(tag, services, kills, seed);
    (rows, log)
}

/// As [`chaos`], also giving the output folder (each run's `launch.log` is in `run-NNN/`).
fn chaos_in(tag: &str, services: &str, kills: usize, seed: u64) -> (Vec<Row>, String, common::Scratch) {
    let out = common::scratch(tag);
    let prefix = common::unique_prefix(tag);
    let run = common::harvey(&[
        "chaos",
        "--services",
        services,
        "--kills",
        &kills.to_string(),
        "--seed",
        &seed.to_string(),
        "--out",
        out.to_str().expect("utf8"),
        "--prefix",
        &prefix,
    ])
    .output()
    .expect("harvey chaos runs");
    let text = format!("{}{}", String::from_utf8_lossy(&run.stdout), String::from_utf8_lossy(&run.stderr));
    (rows(&out.join("chaos.csv"), &text), text, out)
}

fn rows(csv: &Path, log: &str) -> Vec<Row> {
    let text = std::fs::read_to_string(csv).unwrap_or_else(|e| panic!("{}: {e}\n{log}", csv.display()));
    let opt = |s: &str| (!s.is_empty()).then(|| s.parse::<f64>().expect("number"));
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Row {
                service: f[1].to_owned(),
                back_ms: opt(f[3]),
                exit_code: (!f[4].is_empty()).then(|| f[4].parse().expect("code")),
                identical: f[5] == "true",
                missing: f[6].parse().expect("missing"),
                missing_span_s: f[7].parse().expect("span"),
                extra: f[8].parse().expect("extra"),
                end_apart_m: f[10].parse().expect("end apart"),
                shm_left: f[11].parse().expect("shm"),
                missed: f[12] == "true",
                moved_m: opt(f[13]),
            }
        })
        .collect()
}

fn came_back_and_succeeded(rows: &[Row], log: &str) {
    assert!(!rows.is_empty(), "{log}");
    for r in rows {
        assert!(!r.missed, "the kill landed in the mission: {r:?}\n{log}");
        assert_eq!(r.exit_code, Some(0), "{r:?}\n{log}");
        assert!(r.back_ms.is_some_and(|ms| ms < 2_000.0), "{r:?}\n{log}");
        assert_eq!(r.shm_left, 0, "{r:?}");
        if r.service == "executive" {
            // No motion without an executive beyond 0.1 m (in lockstep it holds the chain).
            assert!(r.moved_m.is_some_and(|m| m <= 0.1), "{r:?}");
        }
    }
}

#[test]
fn the_simulated_drv_and_the_bridge_come_back_and_the_recording_is_identical() {
    let (rows, log) = chaos("rs-drv", "sim-drv,denning-bridge", 4, 11);
    came_back_and_succeeded(&rows, &log);
    for r in &rows {
        assert!(r.identical, "{r:?}\n{log}");
        assert_eq!(r.end_apart_m, 0.0, "{r:?}");
    }
    let victims: std::collections::BTreeSet<&str> = rows.iter().map(|r| r.service.as_str()).collect();
    assert_eq!(victims.len(), 2, "both were killed: {rows:?}");
}

#[test]
fn restarted_parties_resume_their_state_and_the_recording_is_identical() {
    let (rows, log) = chaos("rs-state", "encoders,sonar,camera,vision-workers,ums,executive", 7, 5);
    came_back_and_succeeded(&rows, &log);
    for r in &rows {
        assert!(r.identical, "{r:?}\n{log}");
        assert_eq!((r.missing, r.extra), (0, 0), "{r:?}");
    }
}

#[test]
fn a_restarted_recorder_continues_its_recording_losing_at_most_half_a_second() {
    let (rows, log) = chaos("rs-rec", "recorder", 2, 7);
    came_back_and_succeeded(&rows, &log);
    for r in &rows {
        assert_eq!(r.extra, 0, "nothing recorded twice: {r:?}\n{log}");
        assert!(r.missing_span_s <= 0.5, "{r:?}\n{log}");
        assert!(r.end_apart_m < 1e-9, "the recording goes on to the end: {r:?}");
    }
}

#[test]
fn a_killed_supervisor_is_replaced_by_one_that_takes_over_and_the_recording_is_identical() {
    // The keeper starts the services, so they run on while no supervisor watches; the new
    // supervisor takes them and the clock chain over where they are.
    let (rows, log, out) = chaos_in("rs-sup", "supervisor", 2, 3);
    came_back_and_succeeded(&rows, &log);
    for (i, r) in rows.iter().enumerate() {
        assert!(r.identical, "{r:?}\n{log}");
        assert_eq!((r.missing, r.extra), (0, 0), "{r:?}");
        let launch = std::fs::read_to_string(out.join(format!("run-{i:03}/launch.log"))).expect("launch.log");
        assert!(launch.contains("taking over from a supervisor that died"), "{launch}");
        assert!(!launch.contains("restarted"), "no service was started again: {launch}");
    }
}
