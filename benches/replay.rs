//! Replay speed: `harvey replay --check` of the reference recording (the default mission in the
//! hallway, 26 s of simulated time) against real time, and beside it the live deterministic run
//! of the same mission, measured in the same run. Target: replay ≥ 50x real time.
//!
//! `cargo build --release --workspace && cargo bench --bench replay`
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::path::Path;
use std::process::Command;
use std::time::Instant;

const REPS: usize = 5;

fn harvey() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_harvey"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// Runs `args`; returns (wall seconds, combined output). Panics (this is a bench) on failure.
fn timed(args: &[&str]) -> (f64, String) {
    let start = Instant::now();
    let out = harvey().args(args).output().expect("harvey runs");
    let wall = start.elapsed().as_secs_f64();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "harvey {args:?} failed:\n{text}");
    (wall, text)
}

/// The speed the replayer reports: "replay finished: 57.8x real time".
fn replay_factor(text: &str) -> f64 {
    text.split("replay finished: ")
        .nth(1)
        .and_then(|t| t.split('x').next())
        .and_then(|x| x.trim().parse().ok())
        .unwrap_or_else(|| panic!("no replay figure in:\n{text}"))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let dir = std::env::temp_dir().join(format!("harvey-bench-replay-{}", std::process::id()));
    let (run_dir, replay_dir) = (dir.join("live"), dir.join("replay"));
    let reference = Path::new("recordings/reference/default.mcap");
    let sim_s = 26.1;
    let (mut replays, mut replay_walls, mut lives) = (Vec::new(), Vec::new(), Vec::new());
    for rep in 0..REPS {
        let prefix = format!("benchrp{}_{rep}_", std::process::id());
        let (wall, text) = timed(&[
            "replay",
            reference.to_str().expect("utf8"),
            "--check",
            "--prefix",
            &prefix,
            "--run-dir",
            replay_dir.to_str().expect("utf8"),
        ]);
        assert!(text.contains("identical: "), "the replay differs:\n{text}");
        replays.push(replay_factor(&text));
        replay_walls.push(sim_s / wall);
        let (wall, _) = timed(&[
            "run",
            "missions/default.toml",
            "--prefix",
            &format!("benchlv{}_{rep}_", std::process::id()),
            "--run-dir",
            run_dir.to_str().expect("utf8"),
        ]);
        lives.push(sim_s / wall);
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "replay of the reference recording (default mission, {sim_s} s simulated), {REPS} runs, medians:"
    );
    println!("| what | x real time |");
    println!("|---|---:|");
    println!(
        "| replay, ticks fed to the tail's last report (replayer's figure) | {:.1} |",
        median(replays.clone())
    );
    println!("| replay, whole command (start-up, check, shutdown included) | {:.1} |", median(replay_walls));
    println!("| live deterministic run with rendering, whole command | {:.1} |", median(lives));
    let m = median(replays);
    println!("target ≥ 50x: {}", if m >= 50.0 { "met" } else { "NOT met" });
}
