//! 000 §5.6, Table 1, as a mission: plan-level servoing's pose refinement. The robot stands at
//! the start of the hall while the executive believes it 3 or 6 inches to one side; from that
//! belief it finds the mission's landmark vertices by correlation and refines its pose, to
//! within 1.5 in of the truth each time.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_geometry::INCH;
use harvey_msgs::{PoseFix, TruePose};

#[test]
fn expected_poses_inches_off_are_refined_to_within_an_inch_and_a_half() {
    let out = common::run_mission("missions/pose-refine.toml", "prefine");
    assert!(out.status.success() && out.stdout.contains("goal reached (4/4 steps)"), "{}", out.stdout);
    let bytes = out.mcap.as_slice();
    let (mut fixes, mut truth) = (Vec::new(), None);
    for m in mcap::MessageStream::new(bytes).expect("mcap") {
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
    for (f, wanted_in) in fixes.iter().zip([-6.0, -3.0, 3.0, 6.0]) {
        println!(
            "expected {:+.2} in to the side: refined {:.2} in from the truth ({} of {} vertices, {:.2} px rms)",
            (f.expected.y_m - t.y_m) / INCH,
            off(f.refined),
            f.kept,
            f.asked,
            f.rms_px
        );
        // The belief was off by the step's offset (plus what the last refinement left)...
        assert!((((f.expected.y_m - t.y_m) / INCH) - wanted_in).abs() < 1.5, "{f:?}");
        // ...and the vertices put it back.
        assert!(off(f.refined) < 1.5, "refined {} in from the truth: {f:?}", off(f.refined));
        assert!((f.refined.heading_rad - t.heading_rad).abs() < 0.2f64.to_radians(), "{f:?}");
        // The residual: correlation under noise, plus the mount's unknown pitch (3 mrad sd in the
        // shipped worlds: 1.7 px up or down) that a pose (x, y, heading) cannot take up.
        assert!(f.found == f.asked && f.kept + 2 >= f.asked && f.rms_px < 2.5, "{f:?}");
    }
}
