//! 000 §5.6, Table 1, as a mission: plan-level servoing's pose refinement. The robot stands at
//! the start of the hall while the executive believes it 3 or 6 inches to one side; from that
//! belief it finds the mission's landmark vertices by correlation and refines its pose. In the
//! ideal world every fix is within the paper's 1.5 in of the truth; over seeds 1..3 under the
//! shipped sensors (`nominal`) and the `dim` condition, within the budget `docs/evaluation.md`
//! reports (the map's 1 cm errors alone leave 1.8 in median there). In the ideal world the same
//! with the vertices chosen by the world model's landmark selection (000 §5.2,
//! `missions/pose-refine-selected.toml`) instead of listed by hand.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_geometry::INCH;
use harvey_msgs::{PoseFix, TruePose};

/// Each fix's distance from the truth (in), after checking the run and each fix's belief.
fn fix_errors_in(mission: &str, condition: &str, seed: u64) -> Vec<f64> {
    let out = common::run_mission_under(mission, condition, seed, "prefine");
    assert!(out.status.success() && out.stdout.contains("goal reached (4/4 steps)"), "{}", out.stdout);
    let (mut fixes, mut truth) = (Vec::new(), None);
    for m in mcap::MessageStream::new(&out.mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/executive/pose" => fixes.push(harvey_cdr::decode::<PoseFix>(&m.data).expect("fix")),
            "/sim/truth" => {
                truth = Some(harvey_cdr::decode::<TruePose>(&m.data).expect("truth").world_from_robot)
            }
            _ => {}
        }
    }
    let t = truth.expect("truth");
    assert_eq!(fixes.len(), 4, "one refinement per step");
    let off = |p: harvey_msgs::Pose2| (p.x_m - t.x_m).hypot(p.y_m - t.y_m) / INCH;
    fixes
        .iter()
        .zip([-6.0, -3.0, 3.0, 6.0])
        .map(|(f, wanted_in)| {
            println!(
                "{condition} s{seed}: expected {:+.2} in to the side, refined {:.2} in from the truth \
                 ({} of {} vertices, {:.2} px rms)",
                (f.expected.y_m - t.y_m) / INCH,
                off(f.refined),
                f.kept,
                f.asked,
                f.rms_px
            );
            // The belief was off by the step's offset (plus what the last refinement left)...
            assert!((((f.expected.y_m - t.y_m) / INCH) - wanted_in).abs() < 2.5, "{f:?}");
            // ...the heading comes back (the mount's yaw, up to a few mrad, is in it)...
            assert!((f.refined.heading_rad - t.heading_rad).abs() < 0.5f64.to_radians(), "{f:?}");
            // ...and correlation found nearly every vertex, most of them close to where the pose
            // puts them.
            assert!(f.found + 2 >= f.asked && 2 * f.kept >= f.asked && f.rms_px < 2.5, "{f:?}");
            off(f.refined)
        })
        .collect()
}

/// The hand-listed vertices, and those the world model's selection gives (000 §5.2).
const MISSIONS: [&str; 2] = ["missions/pose-refine.toml", "missions/pose-refine-selected.toml"];

#[test]
fn in_the_ideal_world_every_fix_is_within_an_inch_and_a_half() {
    for mission in MISSIONS {
        let errors = fix_errors_in(mission, "ideal", 1);
        assert!(errors.iter().all(|&e| e < 1.5), "{mission}: {errors:?}");
    }
}

/// The listed vertices (the selected ones' fixes are looser under nominal and dim, up to 2.8
/// and 4.3 in over seeds 1..10, so that one fix's miss moves the next's belief further than
/// this test allows: docs/evaluation.md).
#[test]
fn over_seeds_and_conditions_fixes_stay_within_the_budget() {
    let mission = MISSIONS[0];
    let mut worst = Vec::new();
    for condition in ["nominal", "dim"] {
        for seed in 1..=3 {
            let errors = fix_errors_in(mission, condition, seed);
            // Seeds 1..10 gave at most 2.5 in (nominal) and 3.5 in (dim) with the listed vertices,
            // 2.8 and 4.3 with the selected ones.
            assert!(errors.iter().all(|&e| e < 4.0), "{mission} {condition} s{seed}: {errors:?}");
            worst.push(errors.iter().copied().fold(0.0, f64::max));
        }
    }
    worst.sort_by(f64::total_cmp);
    let median = (worst[2] + worst[3]) / 2.0;
    assert!(median < 2.5, "{mission}: median of the runs' worst fixes {median:.2} in: {worst:?}");
}
