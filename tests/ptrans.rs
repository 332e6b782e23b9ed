//! 000 §2 and §4 as a mission: `(ptrans robot-lab teds-office)`. Plan-and-monitor develops the
//! goal over the hallway world's locale graph (through the lab's door, down the hall, through
//! the office's door), checks a milestone after each subgoal, fixes the pose from landmark
//! vertices on the way (000 §5.6), and ends within an inch of Ted's desk.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use common::truth::Truth;
use harvey_geometry::INCH;
use harvey_msgs::{CheckOutcome, PlanSketch, PlanStage, PoseFix, UncertaintyMap};

#[test]
fn ptrans_from_the_robot_lab_ends_within_an_inch_of_teds_desk() {
    let out = common::run_mission("missions/ptrans.toml", "ptrans");
    let (mut fixes, mut truth, mut plans, mut lost_in_lab) =
        (Vec::new(), Truth::default(), Vec::new(), Vec::new());
    for m in mcap::MessageStream::new(&out.mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/executive/pose" => fixes.push(harvey_cdr::decode::<PoseFix>(&m.data).expect("fix")),
            "/executive/plan" => plans.push(harvey_cdr::decode::<PlanSketch>(&m.data).expect("plan")),
            "/ums/map" => {
                let map = harvey_cdr::decode::<UncertaintyMap>(&m.data).expect("map");
                let in_lab = truth.0.last().is_some_and(|t| t.1.y_m > 1.1 && t.1.x_m < 8.0);
                if in_lab && map.lost == 1 {
                    lost_in_lab.push(map.header.stamp_ns as f64 / 1e9);
                }
            }
            Truth::TOPIC => truth.push(&m),
            _ => {}
        }
    }
    for f in &fixes {
        let t = truth.at(f.header.stamp_ns);
        println!(
            "fix at t={:.2}s: truth ({:.3}, {:.3}, {:.2} deg) expected {:.2} in off, refined {:.2} in off, heading {:+.2} deg ({} of {} kept, {:.2} px)",
            f.header.stamp_ns as f64 / 1e9,
            t.x_m,
            t.y_m,
            t.heading_rad.to_degrees(),
            (f.expected.x_m - t.x_m).hypot(f.expected.y_m - t.y_m) / INCH,
            (f.refined.x_m - t.x_m).hypot(f.refined.y_m - t.y_m) / INCH,
            (f.refined.heading_rad - t.heading_rad).to_degrees(),
            f.kept,
            f.asked,
            f.rms_px
        );
    }
    assert!(out.status.success() && out.stdout.contains("goal reached"), "{}\n{}", out.stdout, out.stderr);
    // The lab's meadow asks for no landmark its camera cannot find, so the UMS does not call the
    // robot lost while it crosses the lab (it did from the first turn at the bench, on missed jambs).
    assert!(lost_in_lab.is_empty(), "the UMS reported lost in the lab at {lost_in_lab:?} s");
    // The true path crossed the north wall's line (y = 1) in the lab's doorway, going out, and
    // in the office's, going in, and nowhere else.
    let crossings: Vec<(f64, bool)> = truth
        .0
        .windows(2)
        .filter(|w| (w[0].1.y_m - 1.0).signum() != (w[1].1.y_m - 1.0).signum())
        .map(|w| (w[1].1.x_m, w[1].1.y_m > 1.0))
        .collect();
    println!("crossed y = 1 at {crossings:?}");
    assert!(!crossings.is_empty());
    let (out_of_lab, into_office) = crossings.split_at(crossings.len() / 2);
    assert!(out_of_lab.iter().all(|&(x, _)| (4.0..4.9).contains(&x)), "{crossings:?}");
    assert!(into_office.iter().all(|&(x, _)| (11.0..11.9).contains(&x)), "{crossings:?}");
    assert_eq!(crossings.first().map(|c| c.1), Some(false));
    assert_eq!(crossings.last().map(|c| c.1), Some(true));
    // Pose fixes from eight vertices or more put the robot within an inch or two of the truth
    // (000 §5.6), here taken as their median within 2 in: each vertex is built about 1 cm off its
    // mapped place (the mount's pitch, a few mrad off, is solved for). The weak fixes are the
    // miss (docs/evaluation.md): from five or six vertices at one depth (the end wall 4.5 m off)
    // the worst fix of a run was over 10 in in 11 of 20 nominal seeds (13 with the listed
    // vertices), and at most 23.3 in (this seed; 18.9 listed); the milestone checks recover.
    assert!(fixes.len() >= 5, "{} fixes", fixes.len());
    let mut strong = Vec::new();
    for f in &fixes {
        let t = truth.at(f.header.stamp_ns);
        let off_in = (f.refined.x_m - t.x_m).hypot(f.refined.y_m - t.y_m) / INCH;
        assert!(off_in < 30.0, "a fix {off_in:.2} in off: {f:?}");
        if f.kept >= 8 {
            strong.push(off_in);
        }
    }
    strong.sort_by(f64::total_cmp);
    assert!(!strong.is_empty() && strong[strong.len() / 2] < 2.0, "fixes from 8+ vertices, in: {strong:?}");
    // The published sketch: first from the bench, detailed at the front (to the lab's door and
    // through it) and abstract at the back (the hall to the office); last, arrived.
    let first = plans.first().expect("a plan sketch");
    // (Odometry's start, in hundredths of a foot.)
    assert!((first.places_m[0] - 5.0).abs() < 0.01 && (first.places_m[1] - 4.0).abs() < 0.01, "{first:?}");
    assert_eq!((first.place_count, first.primitive_mask), (5, 0b1011), "{first:?}");
    assert_eq!((first.places_m[2], first.places_m[3]), (4.45, 2.0));
    let last = plans.last().expect("a plan sketch");
    assert_eq!((last.stage, last.last_outcome), (PlanStage::Arrived as u32, CheckOutcome::Reached as u32));
    // The last check: within the goal's 0.5 in, or within two of its fix's standard deviations
    // (a few cm: no further move can do better than the fix tells).
    assert!(last.checks >= 6 && last.last_off_m <= 0.1, "{last:?}");
    let end = truth.last();
    let off_in = (end.x_m - 12.0).hypot(end.y_m - 2.5) / INCH;
    println!("ends {off_in:.2} in from the goal, heading {:.2} deg", end.heading_rad.to_degrees());
    assert!(off_in < 1.0, "ends {off_in:.2} in from the goal");
    // Replayed as nodes of one process, the services give back every message of the run.
    let (replay, _, dir) =
        common::replay_check_with(&out.dir.join("run.mcap"), "ptransip", &["--in-process"]);
    let said = String::from_utf8_lossy(&replay.stdout);
    assert_eq!(replay.status.code(), Some(0), "{said}\n{}", String::from_utf8_lossy(&replay.stderr));
    let summary = mcap::Summary::read(&out.mcap).expect("summary").expect("present");
    let count = summary.stats.expect("stats").message_count as usize;
    assert_eq!(common::agreed(&replay), Some(count), "{said}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The run's final distance from the goal (in), as the mission report gives it.
fn final_error_in(report: &str) -> f64 {
    let line = report.lines().find(|l| l.trim_start().starts_with("final error")).expect("a final error");
    let inches = line.split('(').nth(1).and_then(|s| s.split_whitespace().next()).expect("(N in)");
    inches.parse().expect("a number")
}

#[test]
fn over_seeds_the_goal_is_reached_within_the_budget() {
    let mut nominal = Vec::new();
    for condition in ["ideal", "nominal"] {
        for seed in 1..=3 {
            let out = common::run_mission_under("missions/ptrans.toml", condition, seed, "ptranss");
            assert!(out.stdout.contains("goal reached"), "{condition} s{seed}: {}", out.stdout);
            let off_in = final_error_in(&out.stdout);
            println!("{condition} s{seed}: {off_in:.2} in from the goal");
            if condition == "ideal" {
                // 000 §5's inch, where the map is the world.
                assert!(off_in < 1.0, "{condition} s{seed}: {off_in:.2} in");
            } else {
                // Seeds 1..20 of the nominal sweep ended at most 7.2 in off, half of them within
                // 1.8 in (docs/evaluation.md).
                assert!(off_in < 8.0, "{condition} s{seed}: {off_in:.2} in");
                nominal.push(off_in);
            }
        }
    }
    nominal.sort_by(f64::total_cmp);
    assert!(nominal[1] < 2.5, "nominal median {:.2} in: {nominal:?}", nominal[1]);
}

/// The hand-listed vertices (the comparison `docs/evaluation.md` reports) still take the robot
/// to within 000 §5's inch where the map is the world.
#[test]
fn the_listed_vertices_reach_the_desk_too() {
    let out = common::run_mission_under("missions/ptrans-listed.toml", "ideal", 1, "ptransl");
    assert!(out.stdout.contains("goal reached"), "{}", out.stdout);
    let off_in = final_error_in(&out.stdout);
    assert!(off_in < 1.0, "listed, ideal s1: {off_in:.2} in");
}
