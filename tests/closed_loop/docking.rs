//! Docking (004 §4.2) in the closed loop: from about 40 ft out, the acceptor sequences the
//! phototropic cue, the constrained Hough, region tracking and the sonar; the cart crossing in
//! front of the dock breaks the tracking and the robot recovers as the paper's did.

use harvey_executive::behaviours::Behaviour;
use harvey_executive::{Mode, Output};
use harvey_msgs::MissionState;

use crate::rig::Rig;

#[test]
fn docking_recovers_from_the_cart_and_ends_within_several_inches_of_the_mark() {
    let mut rig = Rig::new("docking");
    rig.run(240.0, |_| false);
    // The acceptor's states as the behaviour published them, each change once.
    let mut trace: Vec<u32> = Vec::new();
    for o in &rig.sent {
        if let Output::Behaviour(b) = o
            && trace.last() != Some(&b.fsa_state)
        {
            trace.push(b.fsa_state);
        }
    }
    let (t, end) = *rig.truth.last().expect("ticked");
    let off_in = crate::docked::off_mark_in(end);
    println!(
        "docked at t = {t:.2} s, {off_in:.2} in from the mark, heading {:.2} deg; trace {trace:?}",
        end.heading_rad.to_degrees()
    );
    assert_eq!(rig.exec.state(), MissionState::Succeeded, "trace {trace:?}");
    crate::docked::assert_docked(&trace, end);
    // Within the mission's own limit: under real-camera noise the acceptor may go round q0-q1
    // several times before the cart has passed.
    assert!(t < 240.0, "docking took {t} s");
    let Mode::Sequenced(run) = &rig.exec.mode else { panic!("a behaviour") };
    let Behaviour::Docking(d) = &run.behaviour else { panic!("docking") };
    assert_eq!(d.done, Some(true));
}
