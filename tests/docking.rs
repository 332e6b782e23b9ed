//! 004 §4.2 as a mission: docking with a workstation from about 40 ft, sequenced by the docking
//! acceptor (missions/fsa/docking.toml). A cart pushed across in front of the dock breaks the
//! tracking, and the robot recovers as the paper's did: q2 -> q1 (the Hough cannot see the dock)
//! -> q0 (move a bit) -> q1 -> q2; it docks within several inches of the mark (004 §1), about 5 in under the worlds' real-camera imperfections.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use common::truth::Truth;
use harvey_msgs::BehaviourState;

/// The behaviour's states, the acceptor's trace (each state once per visit) and the true poses.
fn decode(out: &common::MissionRun) -> (Vec<BehaviourState>, Vec<u32>, Truth) {
    let (mut states, mut truth) = (Vec::new(), Truth::default());
    for m in mcap::MessageStream::new(&out.mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/executive/behaviour" => {
                states.push(harvey_cdr::decode::<BehaviourState>(&m.data).expect("state"))
            }
            Truth::TOPIC => truth.push(&m),
            _ => {}
        }
    }
    let mut trace: Vec<u32> = Vec::new();
    for s in &states {
        if trace.last() != Some(&s.fsa_state) {
            trace.push(s.fsa_state);
        }
    }
    (states, trace, truth)
}

#[test]
fn docking_recovers_from_the_occluding_cart_and_ends_within_several_inches() {
    let out = common::run_mission("missions/docking.toml", "docking");
    let (states, trace, truth) = decode(&out);
    let end = truth.last();
    let off_in = common::docked::off_mark_in(end);
    println!(
        "trace {trace:?}; ends {off_in:.2} in from the mark, heading {:.2} deg",
        end.heading_rad.to_degrees()
    );
    assert!(out.status.success() && out.stdout.contains("goal reached"), "{}\n{}", out.stdout, out.stderr);
    common::docked::assert_docked(&trace, end);
    // Each state drove by its schemas: in q0 move-to-goal, noise, and avoid-static-obstacle
    // past the pillar; in q2 and q3 only move-to-goal (controlled motion).
    let norm = |s: &BehaviourState, k: usize| s.vectors_mps[2 * k].hypot(s.vectors_mps[2 * k + 1]);
    let ballistic: Vec<&BehaviourState> =
        states.iter().filter(|s| s.fsa_state == 0 && s.transitions == 0).collect();
    assert!(ballistic.len() > 400, "{} ticks in q0", ballistic.len());
    assert!(ballistic.iter().all(|s| (norm(s, 0) - 0.3).abs() < 1e-9 && (norm(s, 2) - 0.03).abs() < 1e-9));
    assert!(ballistic.iter().any(|s| norm(s, 1) > 0.05), "never pushed off the pillar");
    let controlled = states.iter().filter(|s| s.fsa_state == 2 || s.fsa_state == 3);
    assert!(controlled.clone().all(|s| norm(s, 1) == 0.0 && norm(s, 2) == 0.0));
    assert!(controlled.clone().any(|s| s.linear_mps > 0.1));
    assert!(states.last().is_some_and(|s| s.achieved == 1 && s.linear_mps == 0.0));

    // The recording replays on its own: it carries the acceptor table the launch names in
    // `[launch] files`, and the services give back every message.
    let (replay, prefix, dir) = common::replay_check(&out.dir.join("run.mcap"), "dockrp");
    let said = String::from_utf8_lossy(&replay.stdout);
    assert_eq!(replay.status.code(), Some(0), "{said}\n{}", String::from_utf8_lossy(&replay.stderr));
    assert!(dir.join("fsa/docking.toml").is_file(), "the acceptor table put back");
    let summary = mcap::Summary::read(&out.mcap).expect("summary").expect("present");
    let count = summary.stats.expect("stats").message_count as usize;
    assert_eq!(common::agreed(&replay), Some(count), "{said}");
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    let _ = std::fs::remove_dir_all(&dir);
    // And as nodes of one process, the FSA sequencer's acceptor table and all.
    let (replay, _, dir) = common::replay_check_with(&out.dir.join("run.mcap"), "dockip", &["--in-process"]);
    let said = String::from_utf8_lossy(&replay.stdout);
    assert_eq!(replay.status.code(), Some(0), "{said}\n{}", String::from_utf8_lossy(&replay.stderr));
    assert_eq!(common::agreed(&replay), Some(count), "{said}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn over_seeds_it_docks_within_several_inches() {
    for condition in ["ideal", "nominal", "harsh"] {
        for seed in 1..=3 {
            let out = common::run_mission_under("missions/docking.toml", condition, seed, "docks");
            let (_, trace, truth) = decode(&out);
            let end = truth.last();
            let off_in = common::docked::off_mark_in(end);
            println!(
                "{condition} s{seed}: trace {trace:?}; {off_in:.2} in from the mark, {:.1} deg",
                end.heading_rad.to_degrees()
            );
            assert!(out.stdout.contains("goal reached"), "{condition} s{seed}: {}", out.stdout);
            // Ballistic, then looking (recognition may fail at first, back to q0), tracked,
            // positioned by sonar, docked.
            assert_eq!(trace[..2], [0, 1], "{condition} s{seed}: {trace:?}");
            assert!(trace.ends_with(&[2, 3, 4]), "{condition} s{seed}: {trace:?}");
            // 004 §1's several inches; an inch and a half where the map is the world (the ideal
            // sweep, seeds 1..10: median 0.66 in, worst 1.09; the posts' heights are read to a
            // pixel, a few degrees of heading at 4 m).
            let bound = if condition == "ideal" { 1.5 } else { 6.0 };
            assert!(off_in < bound, "{condition} s{seed}: {off_in:.2} in from the mark");
            // 004 gives no heading bound; the sweep's runs (seeds 1..20) end within 5.5 degrees
            // of square but one (harsh seed 15, 22: docs/evaluation.md).
            let off_square = harvey_geometry::wrap(end.heading_rad).to_degrees();
            assert!(off_square.abs() < 10.0, "{condition} s{seed}: {off_square:.1} deg off square");
        }
    }
}
