//! 004 §5 as a mission: the pole hunt of the AAAI-92 competition. Ten coded poles stand at
//! places drawn from the seed; the robot finds, goes to and parks by each under the move-to-pole
//! acceptor. At least nine must be visited within the 20 simulated minutes (the paper's robot
//! found eight), judged from the true path, not from what the robot believes.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_msgs::{BehaviourState, TruePose};

#[test]
fn nine_or_more_of_the_ten_poles_are_visited_within_twenty_minutes() {
    let out = common::run_mission("missions/poles.toml", "poles");
    let mut world = harvey_world::load_str(include_str!("../worlds/arena.toml"), "arena").expect("world");
    let poles = world.place_poles(1).expect("room for the poles");
    let (mut truth, mut last) = (Vec::new(), None);
    let mut trace: Vec<u32> = Vec::new();
    for m in mcap::MessageStream::new(&out.mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/sim/truth" => {
                let t = harvey_cdr::decode::<TruePose>(&m.data).expect("truth");
                let p = t.world_from_robot;
                truth.push((t.header.stamp_ns as f64 / 1e9, [p.x_m, p.y_m]));
            }
            "/executive/behaviour" => {
                let b = harvey_cdr::decode::<BehaviourState>(&m.data).expect("state");
                if trace.last() != Some(&b.fsa_state) {
                    trace.push(b.fsa_state);
                }
                last = Some(b);
            }
            _ => {}
        }
    }
    // Visited: the robot's centre came within the world's `visit_m` (0.9 m) of the pole's;
    // parking leaves it 0.6 m from the pole's face, 0.675 m from its centre.
    let field = world.poles.clone().expect("a [poles] table");
    assert_eq!(field.visit_m, 0.9);
    let visits: Vec<(u32, Option<f64>)> =
        poles.iter().map(|p| p.code).zip(field.first_visits(&poles, &truth)).collect();
    println!("visits (code, s): {visits:?}");
    let in_time = visits.iter().filter(|(_, t)| t.is_some_and(|t| t <= 1200.0)).count();
    assert!(out.status.success() && out.stdout.contains("goal reached"), "{}\n{}", out.stdout, out.stderr);
    // The summary counts the same visits, from the recording alone.
    let counted = visits.iter().filter(|(_, t)| t.is_some()).count();
    assert!(out.stdout.contains(&format!("poles visited {counted} of 10")), "{}", out.stdout);
    assert!(in_time >= 9, "{in_time} poles visited in 20 minutes: {visits:?}");
    let parked = last.expect("behaviour states").achieved;
    assert!(parked as usize >= 9 && parked as usize <= in_time, "claims {parked}, truth says {in_time}");
    // Every pole went through the whole acceptor: recognition, the beacon's wait, ballistic
    // motion, parking (q0 q1 q2 q3 q4); q4 also ends a parking that lost its pole (004 §5.3).
    assert!(trace.iter().filter(|&&q| q == 4).count() >= parked as usize);
    assert!(trace.windows(5).filter(|w| w == &[0, 1, 2, 3, 4]).count() >= 9, "{trace:?}");
}

/// The count after `key` in a run's summary line (`poles visited 10 of 10`, `achieved 10`).
fn count_after(stdout: &str, key: &str) -> usize {
    let at = stdout.find(key).unwrap_or_else(|| panic!("no `{key}` in the summary:\n{stdout}")) + key.len();
    stdout[at..].split(|c: char| !c.is_ascii_digit()).next().and_then(|n| n.parse().ok()).expect("a count")
}

#[test]
fn under_harsh_sensors_nine_or_more_poles_are_parked_by_over_seeds() {
    // The harsh condition (conditions/harsh.toml): 5 % sonar dropouts, crosstalk and multipath,
    // 0.1 ft range noise, a dim noisy soft camera 10 mrad off. `harvey sweep missions/poles.toml
    // --seeds 1..10 --conditions nominal,dim,harsh` reaches the goal in every run
    // (docs/evaluation.md); before the parking waited out a dropout, harsh parked by 4-5.
    for seed in 1..=3 {
        let out = common::run_mission_under("missions/poles.toml", "harsh", seed, "poles_harsh");
        assert!(out.status.success() && out.stdout.contains("goal reached"), "harsh s{seed}: {}", out.stdout);
        // Visits as the summary counts them from the recording: the true path against the
        // poles the simulator put down.
        let visited = count_after(&out.stdout, "poles visited ");
        let parked = count_after(&out.stdout, "; achieved ");
        assert!(visited >= 9, "harsh s{seed}: {visited} poles visited");
        assert!(parked >= 9 && parked <= visited, "harsh s{seed}: claims {parked}, truth says {visited}");
    }
}
