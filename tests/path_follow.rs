//! Path following in the campus (001 §2.1) as a mission, `missions/path-follow.toml`: 61 m along
//! the path through two bends by the line finder's centreline (the edges' summed steps where its
//! fit fails), swept over seeds under the nominal, dim and harsh cameras and judged from each
//! recording against the simulator's truth:
//! the robot reaches the path's end and keeps near the true centreline (median and worst); and
//! the UMS's map is smaller with the path's edges as class III landmarks than with the lampposts
//! alone (`missions/path-follow-class-i.toml`, the campus counterpart of 002 Fig. 79 vs 80).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_geometry::distance_to_segment;
use harvey_msgs::{TruePose, UncertaintyMap};

/// The path's centreline (worlds/campus.toml): from the start along x, 45 degrees right, then
/// along x again, and where the mission stops (4 m before its end).
const CENTRELINE: [[f64; 2]; 4] = [[0.0, 0.0], [28.0, 0.0], [40.0, -12.0], [62.0, -12.0]];
const END: [f64; 2] = [58.0, -12.0];
/// The stretch before the first bend both twins drive (m along x).
const FIRST_M: f64 = 26.0;

/// What a run's recording says of it.
#[derive(Debug, Clone, Copy)]
struct Figures {
    /// How far the robot's centre kept from the centreline: median and worst (m).
    median_m: f64,
    worst_m: f64,
    /// How far from the end it stopped (m).
    end_m: f64,
    /// The UMS's map area: median over the run, over its first 26 m (up to the first bend) and
    /// at its end (m²).
    area_median_m2: f64,
    area_first_m2: f64,
    area_end_m2: f64,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn figures(mcap: &[u8]) -> Figures {
    let (mut off, mut areas, mut last) = (Vec::new(), Vec::new(), [0.0; 2]);
    let mut first = Vec::new();
    for m in mcap::MessageStream::new(mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/sim/truth" => {
                let p = harvey_cdr::decode::<TruePose>(&m.data).expect("truth").world_from_robot;
                last = [p.x_m, p.y_m];
                let d = CENTRELINE.windows(2).map(|s| distance_to_segment(s[0], s[1], last));
                off.push(d.fold(f64::INFINITY, f64::min));
            }
            "/ums/map" => {
                let area = harvey_cdr::decode::<UncertaintyMap>(&m.data).expect("map").area_m2;
                areas.push(area);
                if last[0] < FIRST_M {
                    first.push(area);
                }
            }
            _ => {}
        }
    }
    let worst_m = off.iter().copied().fold(0.0, f64::max);
    let area_end_m2 = *areas.last().expect("maps");
    Figures {
        median_m: median(&mut off),
        worst_m,
        end_m: (last[0] - END[0]).hypot(last[1] - END[1]),
        area_median_m2: median(&mut areas),
        area_first_m2: median(&mut first),
        area_end_m2,
    }
}

/// Sweeps `mission` over `seeds` under `conditions`: each run's figures (the log says whether
/// the goal was reached).
fn sweep(mission: &str, tag: &str, seeds: &str, conditions: &[&str]) -> Vec<(String, u64, bool, Figures)> {
    common::sweeps::sweep(mission, tag, seeds, conditions, |c, seed, reached, dir| {
        let f = figures(&std::fs::read(dir.join("run.mcap")).expect("recording"));
        println!(
            "{mission} {c} s{seed}: {} off the centreline median {:.3} worst {:.3} m, {:.2} m from the end, \
             map {:.3} m² (median), {:.3} m² (first 26 m), {:.3} m² (end)",
            if reached { "reached," } else { "FAILED," },
            f.median_m,
            f.worst_m,
            f.end_m,
            f.area_median_m2,
            f.area_first_m2,
            f.area_end_m2
        );
        (c.to_string(), seed, reached, f)
    })
}

// Over seeds 1..10 of each camera every run reached the end, 0.002-0.032 m off the centreline
// (median) and 0.2 m at worst, at a bend (the 3 m path leaves it 1.27 m a side;
// docs/evaluation.md).

#[test]
fn the_robot_follows_the_campus_path_through_both_bends_and_class_iii_shrinks_the_map() {
    let seeds = "1..3";
    let mut rows = sweep("missions/path-follow.toml", "pathfw", seeds, &["nominal", "dim"]);
    rows.extend(sweep("missions/path-follow.toml", "pathfh", seeds, &["harsh"]));
    // Every run that reaches the end kept near the centreline.
    let mut misses = Vec::new();
    for (c, seed, reached, f) in &rows {
        if *reached && (f.end_m > 0.5 || f.worst_m > 0.5 || f.median_m > 0.15) {
            misses.push(format!("{c} s{seed}: {f:?}"));
        }
    }
    // Every run reaches the end (harsh seed 2 lost the path on the gravel bend until a fit had
    // to follow from the prediction: docs/evaluation.md).
    let lost: Vec<String> = rows.iter().filter(|r| !r.2).map(|r| format!("{} s{}", r.0, r.1)).collect();
    if !lost.is_empty() {
        misses.push(format!("lost the path: {lost:?}"));
    }
    // The campus counterpart of 002 Fig. 79 vs 80: the same runs with the lampposts alone. Their
    // map grows until the robot, turning at the first bend by the UMS's pose, misses it: they
    // are compared over the first 26 m.
    let without = sweep("missions/path-follow-class-i.toml", "pathc1", seeds, &["nominal"]);
    for (_, seed, _, f1) in &without {
        let (_, _, _, f3) = rows.iter().find(|r| r.0 == "nominal" && r.1 == *seed).expect("the same seed");
        println!(
            "s{seed}: map area over the first 26 m, median {:.3} m² with the edges, {:.3} m² without",
            f3.area_first_m2, f1.area_first_m2
        );
        if f3.area_first_m2 * 2.0 >= f1.area_first_m2 {
            misses.push(format!("s{seed}: the edges did not halve the map: {f3:?} vs {f1:?}"));
        }
    }
    assert!(misses.is_empty(), "{misses:?}");
}

#[test]
fn a_path_following_run_replays_identically_in_process() {
    common::assert_replays("missions/path-follow.toml", "pathri", &["--in-process"]);
}
