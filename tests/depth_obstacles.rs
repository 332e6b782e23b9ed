//! Obstacle avoidance by depth from motion (001 §2.3) as a mission, `missions/depth-obstacles.toml`:
//! 22 m down the campus path past two cones and a bin that only the simulator has, swept over
//! seeds under the nominal and dim cameras and judged from each recording against the
//! simulator's truth: the robot reaches the goal without touching an obstacle, and 001 Table 1's
//! shape holds: each obstacle's tracked points' depths close in on the truth and their spreads
//! shrink as looks accumulate (a table per obstacle of estimate ± sd against looks).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::collections::BTreeMap;

use common::truth::Truth;
use harvey_msgs::{Pose2, VisionAlgorithm, VisionResult, VisionStatus};
use harvey_world::Mover;

/// The goal and the robot's radius (missions/depth-obstacles.toml, worlds/campus.toml).
const GOAL: [f64; 2] = [22.0, 0.0];
const ROBOT_RADIUS_M: f64 = 0.23;
/// The camera's focal length and centre column (px, worlds/campus.toml).
const FOCAL_PX: f64 = 554.0;
const CX: f64 = 320.0;
/// A tracked point within this of an obstacle's footprint (m) counts as the obstacle's.
const NEAR_M: f64 = 0.3;
/// Table 1 compares looks at like depths (a spread grows with the square of the depth): the
/// obstacles' points whose true depth lies in this band (m).
const BAND_M: (f64, f64) = (4.0, 7.0);

/// Depth estimates of one obstacle's points at one count of looks: (estimate, sd, true depth).
type Samples = BTreeMap<(String, u32), Vec<(f64, f64, f64)>>;

/// The mission's obstacles (`[[mover]]`s of missions/depth-obstacles.toml).
fn movers() -> Vec<Mover> {
    harvey_world::load_movers(&common::repo().join("missions/depth-obstacles.toml")).expect("movers")
}

/// What a run's recording says of it.
#[derive(Debug, Clone, Default)]
struct Figures {
    /// The least clearance between the robot and each obstacle (m; below zero: touched).
    clearance_m: BTreeMap<String, f64>,
    /// Where the robot stopped, from the goal (m).
    end_m: f64,
    samples: Samples,
    /// The obstacles some point of which the workers judged standing off the floor (its depth
    /// known to 10 %, seen in 3 looks: what the executive avoids).
    found: Vec<String>,
}

/// Distance from `p` to the footprint of `m` (0 inside).
fn to_footprint(m: &Mover, p: [f64; 2]) -> f64 {
    let [x, y] = m.at(0.0);
    let n = m.outline.len();
    let inside = (0..n).all(|k| {
        let (a, b) = (m.outline[k], m.outline[(k + 1) % n]);
        (b[0] - a[0]) * (p[1] - y - a[1]) - (b[1] - a[1]) * (p[0] - x - a[0]) >= 0.0
    });
    if inside {
        return 0.0;
    }
    (0..n)
        .map(|k| {
            let (a, b) = (m.outline[k], m.outline[(k + 1) % n]);
            harvey_geometry::distance_to_segment([x + a[0], y + a[1]], [x + b[0], y + b[1]], p)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The depth along the camera's axis from `pose` to the nearest corner of `m`'s footprint.
fn true_depth(m: &Mover, pose: Pose2) -> f64 {
    let [x, y] = m.at(0.0);
    let (s, c) = pose.heading_rad.sin_cos();
    m.outline
        .iter()
        .map(|a| (x + a[0] - pose.x_m) * c + (y + a[1] - pose.y_m) * s)
        .fold(f64::INFINITY, f64::min)
}

fn figures(mcap: &[u8], movers: &[Mover]) -> Figures {
    let mut f = Figures::default();
    let mut truth = Truth::default();
    let mut results = Vec::new();
    for m in mcap::MessageStream::new(mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            Truth::TOPIC => truth.push(&m),
            "/vision/results" => {
                let r = harvey_cdr::decode::<VisionResult>(&m.data).expect("result");
                if r.algorithm == VisionAlgorithm::Depth as u32 && r.status == VisionStatus::Found as u32 {
                    results.push(r);
                }
            }
            _ => {}
        }
    }
    for m in movers {
        let least =
            truth.0.iter().map(|(_, p)| to_footprint(m, [p.x_m, p.y_m])).fold(f64::INFINITY, f64::min);
        f.clearance_m.insert(m.name.clone(), least - ROBOT_RADIUS_M);
    }
    let last = truth.last();
    f.end_m = (last.x_m - GOAL[0]).hypot(last.y_m - GOAL[1]);
    for r in &results {
        // Where the robot truly was when the frame was taken.
        let Some(pose) = truth.at_or_before(r.header.stamp_ns) else { continue };
        for item in r.items[..r.count as usize].iter().skip(1) {
            let [u, _, z, sd, frames, class] = item.values.map(f64::from);
            let seen = pose.apply([z, -(u - CX) * z / FOCAL_PX]);
            let Some(m) = movers.iter().find(|m| to_footprint(m, seen) <= NEAR_M) else { continue };
            let truth = true_depth(m, pose);
            if (BAND_M.0..=BAND_M.1).contains(&truth) {
                f.samples.entry((m.name.clone(), frames as u32)).or_default().push((z, sd, truth));
            }
            if class > 0.5 && frames >= 3.0 && sd <= 0.1 * z && !f.found.contains(&m.name) {
                f.found.push(m.name.clone());
            }
        }
    }
    f
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// 001 Table 1's layout, pooled over runs: per obstacle and count of looks, how many points,
/// the median estimate ± the median spread against the median true depth, and the median
/// error and spread relative to the truth.
fn table(samples: &Samples) -> String {
    let mut out = String::from(
        "| obstacle | looks | points | depth estimate (m) | true depth (m) | error | spread |\n|---|---|---|---|---|---|---|\n",
    );
    for ((name, looks), v) in samples {
        let est = median(v.iter().map(|s| s.0).collect());
        let sd = median(v.iter().map(|s| s.1).collect());
        let truth = median(v.iter().map(|s| s.2).collect());
        let err = median(v.iter().map(|s| (s.0 - s.2).abs() / s.2).collect());
        let spread = median(v.iter().map(|s| s.1 / s.2).collect());
        out += &format!(
            "| {name} | {looks} | {} | {est:.2} ± {sd:.2} | {truth:.2} | {:.1} % | {:.1} % |\n",
            v.len(),
            100.0 * err,
            100.0 * spread
        );
    }
    out
}

/// Sweeps the mission over `seeds` under `conditions`: each run's figures and whether the
/// executive reached the goal.
fn sweep(seeds: &str, conditions: &[&str]) -> Vec<(String, u64, bool, Figures)> {
    let movers = movers();
    common::sweeps::sweep(
        "missions/depth-obstacles.toml",
        "depthob",
        seeds,
        conditions,
        |c, seed, reached, dir| {
            let f = figures(&std::fs::read(dir.join("run.mcap")).expect("recording"), &movers);
            let clearance: Vec<String> = f.clearance_m.iter().map(|(n, c)| format!("{n} {c:.2} m")).collect();
            println!(
                "{c} s{seed}: {} {:.2} m from the goal; clearance {}; found by depth from motion: {:?}",
                if reached { "reached," } else { "FAILED," },
                f.end_m,
                clearance.join(", "),
                f.found
            );
            (c.to_string(), seed, reached, f)
        },
    )
}

// Over seeds 1..10 of each camera, 30 of 30 runs reached the goal by their own reckoning (harsh
// seed 10 only in a later sweep, at 81a39ff), 1.1-4.5 m from it truly (the odometry's turns'
// losses over 22 m, uncorrected), and every run kept 0.47 m or more from every obstacle;
// docs/evaluation.md.

#[test]
fn the_robot_finds_the_cones_by_depth_from_motion_and_drives_round_them() {
    let rows = sweep("1..3", &["nominal", "dim"]);
    let mut misses = Vec::new();
    let mut pooled = Samples::new();
    for (c, seed, reached, f) in &rows {
        if !reached || f.end_m > 4.0 {
            misses.push(format!("{c} s{seed}: reached {reached}, {:.2} m from the goal", f.end_m));
        }
        for (name, clearance) in &f.clearance_m {
            if *clearance < 0.3 {
                misses.push(format!("{c} s{seed}: {clearance:.2} m from {name}"));
            }
        }
        // Depth from motion finds what stands ahead: at least one cone on each run (the robot
        // may pass wide of the other, out of the window).
        if !f.found.iter().any(|n| n.starts_with("cone")) {
            misses.push(format!("{c} s{seed}: no cone found by depth from motion"));
        }
        for (k, v) in &f.samples {
            pooled.entry(k.clone()).or_default().extend(v.iter().copied());
        }
    }
    // cone-1, in the robot's way from the start, found on every run; cone-2 on some: after the
    // detour round cone-1 the robot often passes it wide, out of the window (found on 11 of 30
    // runs over seeds 1..10 of nominal, dim and harsh; 3 of these 6).
    let on = |cone: &str| rows.iter().filter(|r| r.3.found.iter().any(|n| n == cone)).count();
    if on("cone-1") < rows.len() || on("cone-2") == 0 {
        misses.push(format!(
            "cone-1 found on {} of {} runs, cone-2 on {}",
            on("cone-1"),
            rows.len(),
            on("cone-2")
        ));
    }
    // 001 Table 1's shape, over all the obstacles' points at like depths (4-7 m): the spread
    // shrinks as looks accumulate, and the estimate stays within a few per cent of the truth.
    println!("{}", table(&pooled));
    let at = |lo: u32, hi: u32| {
        let v: Vec<(f64, f64)> = pooled
            .iter()
            .filter(|((_, k), _)| (lo..=hi).contains(k))
            .flat_map(|(_, v)| v.iter().map(|s| ((s.0 - s.2).abs() / s.2, s.1 / s.2)))
            .collect();
        (median(v.iter().map(|x| x.0).collect()), median(v.iter().map(|x| x.1).collect()))
    };
    let (early, late) = (at(2, 2), at(4, 8));
    println!(
        "all obstacles at 4-7 m: error {:.3} -> {:.3}, spread {:.3} -> {:.3} (2 looks -> 4-8)",
        early.0, late.0, early.1, late.1
    );
    if late.1 > 0.6 * early.1 || late.0 > 0.1 {
        misses.push(format!("2 looks {early:?}, 4-8 looks {late:?} (error, spread)"));
    }
    assert!(misses.is_empty(), "{misses:?}");
}

#[test]
fn a_depth_obstacles_run_replays_identically_in_process() {
    common::assert_replays("missions/depth-obstacles.toml", "depthri", &["--in-process"]);
}
