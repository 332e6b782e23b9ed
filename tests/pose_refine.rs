//! 000 §5.6, Table 1, as a mission: plan-level servoing's pose refinement. The robot stands at
//! the start of the hall while the executive believes it 3 or 6 inches to one side; from that
//! belief it finds the mission's landmark vertices by correlation and refines its pose. In the
//! ideal world every fix is within the paper's 1.5 in of the truth; over seeds 1..3 under the
//! shipped sensors (`nominal`) and the `dim` condition, within the budget `docs/evaluation.md`
//! reports (the map's 1 cm errors alone left 1.8 in median with the listed vertices). The
//! vertices are chosen by the world model's landmark selection (000 §5.2); in the ideal world
//! the hand-listed ones (`missions/pose-refine-listed.toml`) are held to the same 1.5 in.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use common::truth::Truth;
use harvey_geometry::INCH;
use harvey_msgs::PoseFix;

/// Each fix's distance from the truth (in), after checking the run and each fix's belief.
fn fix_errors_in(mission: &str, condition: &str, seed: u64) -> Vec<f64> {
    let out = common::run_mission_under(mission, condition, seed, "prefine");
    assert!(out.status.success() && out.stdout.contains("goal reached (4/4 steps)"), "{}", out.stdout);
    let (mut fixes, mut truth) = (Vec::new(), Truth::default());
    for m in mcap::MessageStream::new(&out.mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/executive/pose" => fixes.push(harvey_cdr::decode::<PoseFix>(&m.data).expect("fix")),
            Truth::TOPIC => truth.push(&m),
            _ => {}
        }
    }
    let t = truth.last();
    assert_eq!(fixes.len(), 4, "one refinement per step");
    let off = |p: harvey_msgs::Pose2| (p.x_m - t.x_m).hypot(p.y_m - t.y_m) / INCH;
    // Each step moves the belief sideways from the last fix's pose (the first, from where the
    // robot starts, which it knows to the start's error).
    let mut from = (t, 2.5);
    let mut errors = Vec::new();
    for (f, wanted_in) in fixes.iter().zip([-6.0, -3.0, 3.0, 6.0]) {
        println!(
            "{condition} s{seed}: expected {:+.2} in to the side, refined {:.2} in from the truth \
             ({} of {} vertices, {:.2} px rms)",
            (f.expected.y_m - t.y_m) / INCH,
            off(f.refined),
            f.kept,
            f.asked,
            f.rms_px
        );
        // The belief was moved by the step's offset...
        assert!((((f.expected.y_m - from.0.y_m) / INCH) - wanted_in).abs() < from.1, "{f:?}");
        // ...the heading comes back (the mount's yaw, up to a few mrad, is in it)...
        assert!((f.refined.heading_rad - t.heading_rad).abs() < 0.5f64.to_radians(), "{f:?}");
        // ...and correlation found nearly every vertex, most of them close to where the pose
        // puts them.
        assert!(f.found + 2 >= f.asked && 2 * f.kept >= f.asked && f.rms_px < 2.5, "{f:?}");
        errors.push(off(f.refined));
        from = (f.refined, 0.01);
    }
    errors
}

/// The vertices the world model's selection gives (000 §5.2), and the hand-listed ones.
const MISSIONS: [&str; 2] = ["missions/pose-refine.toml", "missions/pose-refine-listed.toml"];

#[test]
fn in_the_ideal_world_every_fix_is_within_an_inch_and_a_half() {
    for mission in MISSIONS {
        let errors = fix_errors_in(mission, "ideal", 1);
        assert!(errors.iter().all(|&e| e < 1.5), "{mission}: {errors:?}");
    }
}

/// The selected vertices, over seeds and conditions (docs/evaluation.md has seeds 1..10 of
/// both missions).
#[test]
fn over_seeds_and_conditions_fixes_stay_within_the_budget() {
    let mission = MISSIONS[0];
    let mut worst = Vec::new();
    for condition in ["nominal", "dim"] {
        for seed in 1..=3 {
            let errors = fix_errors_in(mission, condition, seed);
            // Seeds 1..10 gave at most 2.65 in (nominal) and 3.97 in (dim) with the selected
            // vertices, 2.53 and 3.54 with the listed ones.
            assert!(errors.iter().all(|&e| e < 4.0), "{mission} {condition} s{seed}: {errors:?}");
            worst.push(errors.iter().copied().fold(0.0, f64::max));
        }
    }
    worst.sort_by(f64::total_cmp);
    let median = (worst[2] + worst[3]) / 2.0;
    assert!(median < 2.5, "{mission}: median of the runs' worst fixes {median:.2} in: {worst:?}");
}
