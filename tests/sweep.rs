//! `harvey sweep`: a small sweep of the uncertainty mission over two seeds and two conditions
//! writes its CSV, Markdown and PNG with the runs' own summary figures; bad condition files and an
//! empty seed range are refused naming file, line and key; Ctrl-C stops the runs and keeps the
//! finished rows.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

/// The "final error X m (Y in)" of a summary, as printed.
fn final_error(summary: &str) -> String {
    let line = summary.lines().find(|l| l.contains("final error")).expect("final error line");
    line.trim().trim_start_matches("final error ").trim_end_matches(" from the goal").to_owned()
}

/// Runs a sweep command to its end: its output and its process id.
fn output(cmd: &mut std::process::Command) -> (std::process::Output, u32) {
    let child = cmd
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("starts");
    let pid = child.id();
    (child.wait_with_output().expect("runs"), pid)
}

/// No hidden launch or world copies of sweep `pid` left next to the missions.
fn no_copies_left(pid: u32) {
    let left: Vec<String> = std::fs::read_dir(common::repo().join("missions"))
        .expect("missions")
        .filter_map(|e| Some(e.ok()?.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.starts_with(&format!(".sweep-{pid}-")))
        .collect();
    assert_eq!(left, Vec::<String>::new());
}

#[test]
fn a_sweep_tabulates_each_runs_figure_per_seed_and_condition() {
    let (prefix, out) = (common::unique_prefix("sw"), common::scratch("sweep"));
    let out_s = out.to_str().expect("utf8");
    let args = ["sweep", "missions/uncertainty.toml", "--seeds", "1..2", "--conditions", "nominal"];
    let (run, pid) = output(common::harvey(&args).args([
        "--conditions",
        "dim",
        "--jobs",
        "2",
        "--keep",
        "--out",
        out_s,
        "--prefix",
        &prefix,
    ]));
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&run.stderr));
    assert!(stdout.contains("nominal: 2/2 succeeded") && stdout.contains("dim: 2/2 succeeded"), "{stdout}");
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    no_copies_left(pid);

    let csv = std::fs::read_to_string(out.join("sweep.csv")).expect("csv");
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    let keys: Vec<(&str, &str, &str)> = rows.iter().map(|r| (r[0], r[1], r[2])).collect();
    assert_eq!(
        keys,
        [
            ("nominal", "1", "reached"),
            ("nominal", "2", "reached"),
            ("dim", "1", "reached"),
            ("dim", "2", "reached")
        ]
    );
    // Each row's figure is the one its run printed in its summary.
    for r in &rows {
        let log = std::fs::read_to_string(
            out.join("runs").join(format!("{}-s{}", r[0], r[1])).join("harvey-run.log"),
        )
        .expect("log");
        let inches: f64 = r[5].parse().expect("figure");
        assert_eq!(r[4], "final error (in)");
        assert!(final_error(&log).ends_with(&format!("({inches:.2} in)")), "{r:?}: {}", final_error(&log));
        assert!(Path::new(r[14]).is_file(), "--keep keeps {}", r[14]);
        // Each run's UMS maps checked against the simulator's truth, as its summary counts them.
        let (without, maps): (usize, usize) = (r[16].parse().expect("count"), r[17].parse().expect("count"));
        let said = format!("the true pose inside the uncertainty map: {} of {maps} maps", maps - without);
        assert!(maps > 100 && log.contains(&said), "{r:?}: {said}\n{log}");
    }
    // The nominal seed 1 is the mission as `harvey run` runs it.
    let single = common::run_mission("missions/uncertainty.toml", "sw1");
    assert!(single.status.success());
    let log = std::fs::read_to_string(out.join("runs/nominal-s1/harvey-run.log")).expect("log");
    assert_eq!(final_error(&log), final_error(&single.stdout));
    // The dim runs ran in the dim world (their recordings carry it), the nominal ones in the world's own.
    let camera = |run: &str| {
        let rec =
            harvey_recording::Recording::open(&out.join("runs").join(run).join("run.mcap")).expect("mcap");
        let (w, _) = rec.world().expect("world").expect("a world");
        (w.camera.illumination, w.camera.noise_sd, w.camera.vignetting)
    };
    assert_eq!(camera("dim-s2"), (170.0, 5.0, 0.25));
    assert_eq!(camera("nominal-s2"), (220.0, 3.0, 0.2), "the hallway's own camera");

    let md = std::fs::read_to_string(out.join("sweep.md")).expect("md");
    assert!(md.contains("| condition | runs | successes | success rate | median | p90 | worst |"), "{md}");
    assert!(md.contains("| nominal | 2 | 2 | 100 % |") && md.contains("| dim | 2 | 2 | 100 % |"), "{md}");
    assert_eq!(md.lines().filter(|l| l.starts_with("| dim | ") || l.starts_with("| nominal | ")).count(), 6);
    let png = image::open(out.join("sweep.png")).expect("a PNG");
    assert_eq!((png.width(), png.height()), (960, 600));
}

#[test]
fn bad_conditions_and_empty_seed_ranges_are_refused_naming_file_line_and_key() {
    let dir = common::scratch("sweep-bad");
    let cases = [
        ("unknown.toml", "[camera]\nnoise_sd = 2\nfisheye = 1\n", ":3: key `camera.fisheye`"),
        ("vignette.toml", "[camera]\nvignetting = 1.0\n", ":2: key `camera.vignetting`"),
        ("noise.toml", "# negative noise\n[camera]\nnoise_sd = -0.5\n", ":3: key `camera.noise_sd`"),
    ];
    for (name, text, want) in cases {
        let file = dir.join(name);
        std::fs::write(&file, text).expect("write");
        let (out, pid) =
            output(common::harvey(&["sweep", "missions/uncertainty.toml", "--seeds", "1..2"]).args([
                "--conditions",
                file.to_str().expect("utf8"),
                "--out",
                dir.join("out").to_str().expect("utf8"),
            ]));
        no_copies_left(pid);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(&format!("{}{want}", file.display())), "{name}: {err}");
    }
    let (out, _) = output(&mut common::harvey(&["sweep", "missions/uncertainty.toml", "--seeds", "3..2"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("argument `--seeds 3..2`: the range is empty"), "{err}");
    assert!(!dir.join("out").exists(), "nothing runs");
}

#[test]
fn ctrl_c_stops_the_runs_and_keeps_the_finished_rows() {
    let (prefix, out) = (common::unique_prefix("swi"), common::scratch("sweep-int"));
    let mut child = common::harvey(&["sweep", "missions/uncertainty.toml", "--seeds", "1..6", "--jobs", "1"])
        .args(["--out", out.to_str().expect("utf8"), "--prefix", &prefix])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("starts");
    let deadline = Instant::now() + Duration::from_secs(60);
    let rows =
        || std::fs::read_to_string(out.join("sweep.csv")).map_or(0, |c| c.lines().count().saturating_sub(1));
    while rows() < 1 {
        assert!(Instant::now() < deadline, "no row within 60 s");
        std::thread::sleep(Duration::from_millis(20));
    }
    common::signal(&child, libc::SIGINT);
    let status = common::wait_exit(&mut child, Duration::from_secs(60));
    let mut stdout = String::new();
    std::io::Read::read_to_string(&mut child.stdout.take().expect("stdout"), &mut stdout).expect("read");
    assert_eq!(status.code(), Some(130), "{stdout}");
    let kept = rows();
    assert!((1..6).contains(&kept), "{kept} rows");
    assert!(
        stdout.contains(&format!("the {kept} finished rows of 6 are in {}", out.join("sweep.csv").display())),
        "{stdout}"
    );
    for seed in 1..=6 {
        let p = format!("{prefix}c0s{seed}_");
        assert_eq!(common::processes_with_prefix(&p), Vec::<u32>::new(), "{p}");
        assert_eq!(common::shm_leftovers(&p), Vec::<String>::new(), "{p}");
    }
    no_copies_left(child.id());
}
