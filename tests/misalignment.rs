//! 000 §5.5 Fig. 10's experiment (issue 19 item 6): action-level servoing down the hallway (40 ft
//! in 2 ft increments, servoed on the exit sign) by a robot whose camera mount is turned 0.000,
//! 0.001 or 0.010 rad to the left and which takes it to be aligned
//! (`missions/hallway-40ft-uncalibrated.toml`, `conditions/mount-*.toml`). The paper's result:
//! 0.001 rad costs nothing that matters, 0.010 rad bends the path off the line. The offsets along
//! the run are printed side by side (the figure), and the remedy is checked too: the shipped
//! `hallway-40ft`, which measures its mount on the sign first, holds the line under 0.010 rad.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_geometry::{FT, INCH};
use harvey_msgs::TruePose;

const SEEDS: u64 = 5;

/// The true path's signed offsets from the line (in, left positive) at every 4 ft, and the
/// largest offset over the run (in).
fn offsets(mcap: &[u8]) -> (Vec<f64>, f64) {
    let mut truth: Vec<[f64; 2]> = Vec::new();
    for m in mcap::MessageStream::new(mcap).expect("mcap") {
        let m = m.expect("message");
        if m.channel.topic == "/sim/truth" {
            let p = harvey_cdr::decode::<TruePose>(&m.data).expect("truth").world_from_robot;
            truth.push([p.x_m, p.y_m]);
        }
    }
    let at = |ft: f64| truth.iter().find(|p| p[0] >= ft * FT).map_or(f64::NAN, |p| p[1] / INCH);
    let worst = truth.iter().map(|p| p[1].abs() / INCH).fold(0.0, f64::max);
    ((1..=9).map(|k| at(4.0 * f64::from(k))).collect(), worst)
}

/// Sweeps `mission` over seeds 1..=SEEDS under `conditions`: per condition, each seed's offsets.
fn sweep(mission: &str, conditions: &[&str], tag: &str) -> Vec<Vec<(Vec<f64>, f64)>> {
    let (prefix, out) = (common::unique_prefix(tag), common::scratch(tag));
    let (seeds, list) = (format!("1..{SEEDS}"), conditions.join(","));
    let args = ["sweep", mission, "--seeds", &seeds, "--conditions", &list, "--in-process"];
    let run = common::harvey(&args)
        .args(["--jobs", "2", "--keep", "--out", out.to_str().expect("utf8"), "--prefix", &prefix])
        .output()
        .expect("runs");
    let said = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{said}\n{}", String::from_utf8_lossy(&run.stderr));
    conditions
        .iter()
        .map(|c| {
            (1..=SEEDS)
                .map(|seed| {
                    let dir = out.join("runs").join(format!("{c}-s{seed}"));
                    offsets(&std::fs::read(dir.join("run.mcap")).expect("recording"))
                })
                .collect()
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[test]
fn a_misaligned_camera_bends_the_servoed_path_and_measuring_the_mount_straightens_it() {
    let cases = ["mount-aligned", "mount-yaw-1mrad", "mount-yaw-10mrad"];
    let runs = sweep("missions/hallway-40ft-uncalibrated.toml", &cases, "fig10");
    println!("offset from the line (in, left +), median over seeds 1..{SEEDS}, uncalibrated robot:");
    println!("{:>6} {:>14} {:>14} {:>14}", "ft", cases[0], cases[1], cases[2]);
    for k in 0..9 {
        let m: Vec<f64> = runs.iter().map(|seeds| median(seeds.iter().map(|s| s.0[k]).collect())).collect();
        println!("{:>6} {:>14.2} {:>14.2} {:>14.2}", 4 * (k + 1), m[0], m[1], m[2]);
    }
    let worst: Vec<Vec<f64>> = runs.iter().map(|seeds| seeds.iter().map(|s| s.1).collect()).collect();
    for (c, w) in cases.iter().zip(&worst) {
        println!("{c}: worst offset per seed {w:.2?} in");
    }
    let (aligned, small, large) =
        (median(worst[0].clone()), median(worst[1].clone()), median(worst[2].clone()));
    // The paper: 0.001 rad is as good as aligned, 0.010 rad bends the path. Over 12 m the sign is
    // 4-16 m off; 10 mrad of yaw taken for a heading error moves the path by centimetres.
    assert!(small < 1.0 && aligned < 1.0, "aligned {aligned:.2} in, 0.001 rad {small:.2} in");
    assert!(large > 1.5, "0.010 rad: {large:.2} in");
    assert!(large > 2.0 * small.max(aligned), "0.010 rad {large:.2} in against {small:.2} and {aligned:.2}");
    // On every seed the larger misalignment takes the path further off than the smaller.
    for (seed, (large, small)) in worst[2].iter().zip(&worst[1]).enumerate() {
        assert!(large > small, "seed {}: {large:.2} vs {small:.2} in", seed + 1);
    }

    // The remedy: measuring the mount on the sign before the first increment.
    let calibrated = sweep("missions/hallway-40ft.toml", &["mount-yaw-10mrad"], "fig10c");
    let held: Vec<f64> = calibrated[0].iter().map(|s| s.1).collect();
    println!("hallway-40ft (mount measured) under 0.010 rad: worst offset per seed {held:.2?} in");
    // tests/hallway.rs's nominal budget: the paper's 0.3 in plus the map's 0.28 in.
    assert!(held.iter().all(|&h| h <= 0.58), "{held:.2?}");
}

#[test]
fn an_uncalibrated_run_replays_identically_in_process() {
    common::assert_replays("missions/hallway-40ft-uncalibrated.toml", "fig10rp", &["--in-process"]);
}
