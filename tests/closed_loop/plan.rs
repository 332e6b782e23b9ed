//! Plan-and-monitor (000 §2, §4) in the closed loop: `(ptrans robot-lab teds-office)` developed
//! over the hallway's locale graph, milestone by milestone with pose fixes on the way, from the
//! lab bench to within an inch of Ted's desk.

use harvey_executive::{Mode, Output};
use harvey_geometry::INCH;
use harvey_msgs::{MissionState, PlanStage};

use crate::rig::Rig;

#[test]
fn ptrans_from_the_lab_bench_ends_within_an_inch_of_teds_desk() {
    let mut rig = Rig::new("ptrans");
    rig.run(300.0, |_| false);
    let (t, end) = *rig.truth.last().expect("ticked");
    let off_in = (end.x_m - 12.0).hypot(end.y_m - 2.5) / INCH;
    let Mode::Plan(plan) = &rig.exec.mode else { panic!("plan-and-monitor") };
    let (checks, replans) = (plan.monitor.checks.len(), plan.monitor.replans);
    println!(
        "arrived at t = {t:.2} s, {off_in:.2} in from the goal, heading {:.2} deg; {checks} checks, {replans} \
         replans, {} fixes",
        end.heading_rad.to_degrees(),
        plan.script.fixes
    );
    assert_eq!(rig.exec.state(), MissionState::Succeeded);
    assert!(off_in < 1.0, "ends {off_in:.2} in from the goal");
    assert!((end.heading_rad.to_degrees() - 60.0).abs() < 2.0, "{end:?}");
    assert!(plan.script.fixes >= 5 && checks >= 6, "{} fixes, {checks} checks", plan.script.fixes);
    let last = rig.sent.iter().rev().find_map(|o| if let Output::Plan(p) = o { Some(*p) } else { None });
    assert_eq!(last.map(|p| p.stage), Some(PlanStage::Arrived as u32));
}
