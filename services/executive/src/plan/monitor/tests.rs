//! Plan-and-monitor's tests on the hallway world: both doors, retries, the plan developed afresh
//! after a far miss and after lost, the rules near the goal.

use super::*;

fn goal() -> PtransGoal {
    PtransGoal {
        to: "teds-office".into(),
        goal_m: [12.0, 2.5],
        goal_heading_deg: 60.0,
        approach_m: 0.4,
        door_depth_m: 1.0,
        milestone_m: 0.15,
        goal_tolerance_m: 0.0127,
        escalate_m: 0.5,
        attempts: 3,
        back_off_m: 0.3,
    }
}

fn hallway() -> World {
    harvey_world::load_str(include_str!("../../../../../worlds/hallway.toml"), "hallway").expect("world")
}

/// Runs the plan on a robot that falls `loss` short of every move while odometry says it
/// went the whole way; every pose fix tells the truth. `kick` moves the robot unbeknown to
/// it once, after the check of milestone `kick.0`.
fn run(start: Pose2, loss: f64, kick: Option<(&str, [f64; 2])>) -> (Monitor, Pose2) {
    let mut m = Monitor::new(goal(), hallway());
    let (mut truth, mut belief, mut fixes) = (start, start, 0);
    let mut kicked = false;
    for _ in 0..200 {
        if let Some((after, [dx, dy])) = kick
            && !kicked
            && m.checks.iter().any(|c| c.milestone == after)
        {
            (truth.x_m, truth.y_m, kicked) = (truth.x_m + dx, truth.y_m + dy, true);
        }
        match m.next(belief, fixes).expect("plans") {
            Next::Arrived => return (m, truth),
            Next::Steps(steps) => {
                for s in steps {
                    if let Some(deg) = s.turn_deg {
                        truth.heading_rad += deg.to_radians();
                        belief.heading_rad += deg.to_radians();
                    }
                    if let Some(d) = s.move_m {
                        let (c, sn) = (truth.heading_rad.cos(), truth.heading_rad.sin());
                        (truth.x_m, truth.y_m) =
                            (truth.x_m + d * (1.0 - loss) * c, truth.y_m + d * (1.0 - loss) * sn);
                        let (c, sn) = (belief.heading_rad.cos(), belief.heading_rad.sin());
                        (belief.x_m, belief.y_m) = (belief.x_m + d * c, belief.y_m + d * sn);
                    }
                    if s.refine_pose {
                        (belief, fixes) = (truth, fixes + 1);
                    }
                }
            }
        }
    }
    panic!("never arrived: {:?}", m.checks);
}

const BENCH: Pose2 = Pose2 { x_m: 5.0, y_m: 4.0, heading_rad: -std::f64::consts::FRAC_PI_2 };

#[test]
fn the_plan_goes_through_both_doors_and_retries_a_short_leg() {
    let (m, end) = run(BENCH, 0.042, None);
    let reached: Vec<&str> =
        m.checks.iter().filter(|c| c.outcome == Outcome::Reached).map(|c| c.milestone.as_str()).collect();
    assert_eq!(
        reached,
        [
            "robot-lab-side-of-door-0",
            "hallway-side-of-door-0",
            "hallway-side-of-door-1",
            "teds-office-side-of-door-1",
            "approach",
            "goal"
        ]
    );
    // 4.2 % short of 7 m down the hall is 0.29 m: missed, retried from there.
    let miss = m.checks.iter().find(|c| c.outcome == Outcome::Retried).expect("a retry");
    assert_eq!(miss.milestone, "hallway-side-of-door-1");
    assert!((miss.off_m - 0.042 * 7.0).abs() < 0.02, "{miss:?}");
    assert_eq!(m.replans, 0);
    assert!((end.x_m - 12.0).hypot(end.y_m - 2.5) <= 0.0127, "{end:?}");
    assert!((wrap(end.heading_rad) - 60f64.to_radians()).abs() < 0.01, "{end:?}");
}

#[test]
fn a_milestone_missed_by_far_develops_the_plan_afresh_from_there() {
    // Carried 1.2 m back up the hall after leaving the lab: the office door's milestone is
    // missed by far, and the plan is developed again from where the robot is.
    let (m, end) = run(BENCH, 0.0, Some(("hallway-side-of-door-0", [-1.2, 0.0])));
    let miss = m.checks.iter().find(|c| c.outcome == Outcome::Replanned).expect("a replan");
    assert_eq!(miss.milestone, "hallway-side-of-door-1");
    assert!((miss.off_m - 1.2).abs() < 1e-6, "{miss:?}");
    assert_eq!(m.replans, 1);
    assert!((end.x_m - 12.0).hypot(end.y_m - 2.5) <= 0.0127, "{end:?}");
}

#[test]
fn when_the_ums_reports_lost_it_relocates_and_develops_the_plan_afresh() {
    let mut m = Monitor::new(goal(), hallway());
    let Ok(Next::Steps(first)) = m.next(BENCH, 0) else { panic!("steps") };
    assert!(first.iter().any(|s| s.turn_deg.is_some()));
    m.lost();
    m.lost();
    // At the next step boundary: a pose fix, then a plan developed from where that says.
    assert_eq!(m.next(BENCH, 0), Ok(Next::Steps(vec![fix()])));
    assert_eq!((m.relocations, m.replans, m.sketch.len()), (1, 0, 0));
    let fixed = Pose2 { x_m: 4.45, y_m: 3.0, heading_rad: -std::f64::consts::FRAC_PI_2 };
    let Ok(Next::Steps(_)) = m.next(fixed, 1) else { panic!("steps") };
    assert_eq!(m.sketch[0].from.at, [4.45, 3.0]);
    assert_eq!(m.sketch[0].to.name, "robot-lab-side-of-door-0");
}

#[test]
fn near_the_goal_it_moves_straight_or_backs_off_rather_than_turn_far() {
    // 2 cm short, dead ahead: one move. 3 cm to the side: back off, aim, come in again.
    let g = Pose2 { x_m: 12.0, y_m: 2.5, heading_rad: 60f64.to_radians() };
    let near = |ahead: f64, left: f64| {
        let (c, s) = (g.heading_rad.cos(), g.heading_rad.sin());
        Pose2 { x_m: g.x_m - ahead * c + left * s, y_m: g.y_m - ahead * s - left * c, ..g }
    };
    let one_move = |at: Pose2| match Monitor::new(goal(), hallway()).next(at, 0) {
        Ok(Next::Steps(s)) if s.len() == 1 => s[0].move_m,
        other => panic!("{other:?}"),
    };
    assert!(one_move(near(0.02, 0.0)).is_some_and(|d| (d - 0.02).abs() < 1e-9));
    assert!(one_move(near(0.0, 0.03)).is_some_and(|d| (d + 0.45).abs() < 1e-9));
    let bad = PtransGoal { to: "attic".into(), ..goal() };
    assert_eq!(Monitor::new(bad, hallway()).next(BENCH, 0), Err(PlanError::UnknownLocale("attic".into())));
}

#[test]
fn a_fixed_check_within_two_of_the_fix_s_deviations_is_reached() {
    // The first milestone (0.15 m tolerance) checked 0.3 m off.
    let outcome = |fix_sd_m: f64, fixed: bool| {
        let mut m = Monitor::new(goal(), hallway());
        let Ok(Next::Steps(_)) = m.next(BENCH, 0) else { panic!("steps") };
        let sub = m.sketch[0].clone();
        m.last_fix_sd(fix_sd_m);
        m.check(&sub, BENCH, 0.3, fixed).expect("checks");
        m.checks.last().expect("a check").outcome
    };
    assert_eq!(outcome(0.2, true), Outcome::Reached, "a fix good to 0.2 m cannot tell 0.3 m");
    assert_eq!(outcome(0.1, true), Outcome::Retried);
    assert_eq!(outcome(0.2, false), Outcome::Retried, "dead reckoning alone is taken at its word");
}
