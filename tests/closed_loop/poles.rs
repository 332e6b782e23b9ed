//! The pole hunt (004 §5) in the closed loop, shortened: the first three of the arena's coded
//! poles found, gone to and parked by, judged from the simulator's true path.

use harvey_executive::Mode;
use harvey_executive::behaviours::Behaviour;

use crate::launch::Launch;
use crate::rig::Rig;

/// The hunt's poles parked by so far.
fn parked(rig: &Rig) -> usize {
    match &rig.exec.mode {
        Mode::Sequenced(run) => match &run.behaviour {
            Behaviour::Poles(h) => h.visited.len(),
            _ => 0,
        },
        _ => 0,
    }
}

#[test]
fn the_hunt_visits_three_poles_within_five_simulated_minutes() {
    let launch = Launch::read("poles");
    let mut world = launch.world(None, false, None);
    let poles = world.place_poles(launch.seed).expect("room for the poles");
    let field = world.poles.clone().expect("a [poles] table");
    let mut rig = Rig::new("poles");
    rig.run(300.0, |r| parked(r) >= 3);
    let path: Vec<(f64, [f64; 2])> = rig.truth.iter().map(|&(t, p)| (t, [p.x_m, p.y_m])).collect();
    // Visited: the robot's centre came within the field's `visit_m` of a pole's.
    let visits = field.first_visits(&poles, &path);
    let mut firsts: Vec<f64> = visits.iter().flatten().copied().collect();
    firsts.sort_by(f64::total_cmp);
    println!("parked by {} poles by t = {:.1} s; first visits {firsts:.1?}", parked(&rig), rig.time_s());
    assert!(parked(&rig) >= 3, "the hunt parked by {} poles in {:.0} s", parked(&rig), rig.time_s());
    assert!(firsts.len() >= 3, "the true path visited {} poles: {visits:?}", firsts.len());
    assert!(firsts[2] < 300.0);
}
