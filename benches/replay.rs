//! Replay speed: `harvey replay --check` of the reference recording (the default mission in the
//! hallway, 26 s of simulated time) against real time, and beside it the live deterministic run
//! of the same mission, measured in the same run, once per vision-kernel SIMD path the CPU has
//! (`HARVEY_SIMD`, which the services inherit), so what the kernels' paths bring to a whole
//! mission is a same-run ratio; and the replay in one process (`--in-process`), whose ratio to
//! the multi-process replay is same-run too. Targets: replay ≥ 50x real time; in process ≥ 10x
//! the multi-process replay and ≥ 500x real time (issue 15).
//!
//! `cargo build --release --workspace && cargo bench --bench replay`
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use harvey_vision::simd::{self, Path as SimdPath};

const REPS: usize = 5;

fn harvey(path: SimdPath) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_harvey"));
    c.current_dir(env!("CARGO_MANIFEST_DIR")).env(simd::ENV, path.name());
    c
}

/// Runs `args` with the vision kernels on `path`; returns (wall seconds, combined output).
/// Panics (this is a bench) on failure.
fn timed(path: SimdPath, args: &[&str]) -> (f64, String) {
    let start = Instant::now();
    let out = harvey(path).args(args).output().expect("harvey runs");
    let wall = start.elapsed().as_secs_f64();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "harvey {args:?} failed:\n{text}");
    (wall, text)
}

/// The speed the replayer reports: "replay finished: 57.8x real time"; in process, the line
/// "replay: N ticks, ...: 90.6x real time".
fn replay_factor(text: &str) -> f64 {
    let line = text.lines().find(|l| l.starts_with("replay: ") && l.ends_with("x real time"));
    line.map(|l| l.rsplit(": ").next().unwrap_or(l))
        .or_else(|| text.split("replay finished: ").nth(1))
        .and_then(|t| t.split('x').next())
        .and_then(|x| x.trim().parse().ok())
        .unwrap_or_else(|| panic!("no replay figure in:\n{text}"))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One path's figures: the replayer's own, the whole replay command's, the live run's.
#[derive(Default)]
struct Figures {
    replay: Vec<f64>,
    replay_wall: Vec<f64>,
    inproc: Vec<f64>,
    inproc_wall: Vec<f64>,
    live: Vec<f64>,
}

fn main() {
    let dir = std::env::temp_dir().join(format!("harvey-bench-replay-{}", std::process::id()));
    let (run_dir, replay_dir) = (dir.join("live"), dir.join("replay"));
    let reference = Path::new("recordings/reference/default.mcap");
    let sim_s = 26.1;
    let paths = SimdPath::available();
    let mut figures: Vec<Figures> = paths.iter().map(|_| Figures::default()).collect();
    // Paths interleaved within each round, so a noisy stretch of the machine hits them alike.
    for rep in 0..REPS {
        for (k, &path) in paths.iter().enumerate() {
            let tag = format!("{}{rep}{}", std::process::id(), path.name());
            let (wall, text) = timed(
                path,
                &[
                    "replay",
                    reference.to_str().expect("utf8"),
                    "--check",
                    "--prefix",
                    &format!("benchrp{tag}_"),
                    "--run-dir",
                    replay_dir.to_str().expect("utf8"),
                ],
            );
            assert!(text.contains("identical: "), "the replay on {path} differs:\n{text}");
            figures[k].replay.push(replay_factor(&text));
            figures[k].replay_wall.push(sim_s / wall);
            let (wall, text) = timed(
                path,
                &[
                    "replay",
                    reference.to_str().expect("utf8"),
                    "--check",
                    "--in-process",
                    "--run-dir",
                    replay_dir.to_str().expect("utf8"),
                ],
            );
            assert!(text.contains("identical: "), "the in-process replay on {path} differs:\n{text}");
            figures[k].inproc.push(replay_factor(&text));
            figures[k].inproc_wall.push(sim_s / wall);
            let (wall, _) = timed(
                path,
                &[
                    "run",
                    "missions/default.toml",
                    "--prefix",
                    &format!("benchlv{tag}_"),
                    "--run-dir",
                    run_dir.to_str().expect("utf8"),
                ],
            );
            figures[k].live.push(sim_s / wall);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!("CPU: {}; SIMD features: {}", simd::cpu_model(), simd::cpu_features());
    println!(
        "replay of the reference recording (default mission, {sim_s} s simulated), {REPS} runs per \
         vision-kernel path (HARVEY_SIMD), interleaved, medians in x real time:"
    );
    let header: Vec<String> = paths.iter().map(|p| p.name().to_owned()).collect();
    println!("| what | {} |", header.join(" | "));
    println!("|---|{}", "---:|".repeat(paths.len()));
    let row = |what: &str, pick: &dyn Fn(&Figures) -> Vec<f64>| {
        let cells: Vec<String> = figures.iter().map(|f| format!("{:.1}", median(pick(f)))).collect();
        println!("| {what} | {} |", cells.join(" | "));
    };
    row("replay, ticks fed to the tail's last report (replayer's figure)", &|f| f.replay.clone());
    row("replay, whole command (start-up, check, shutdown included)", &|f| f.replay_wall.clone());
    row("replay in process, first tick to the file finished (the replay's figure)", &|f| f.inproc.clone());
    row("replay in process, whole command (check included)", &|f| f.inproc_wall.clone());
    row("live deterministic run with rendering, whole command", &|f| f.live.clone());
    let met = |ok: bool| if ok { "met" } else { "NOT met" };
    let best = figures.last().map_or(0.0, |f| median(f.replay.clone()));
    println!("target ≥ 50x on the fastest path: {}", met(best >= 50.0));
    for (f, p) in figures.iter().zip(&paths) {
        let (multi, one) = (median(f.replay.clone()), median(f.inproc.clone()));
        let ratio = one / multi;
        println!(
            "{p}: in process / multi-process (the replays' figures, same run) = {ratio:.2}x (target ≥ 10x: {}); \
             in process {one:.1}x real time (target ≥ 500x: {})",
            met(ratio >= 10.0),
            met(one >= 500.0)
        );
    }
}
