//! CMU's visual navigation (003) as a mission (`missions/neptune.toml`): across the lab to the
//! goal in stop-go-stop steps, the position model from stereo alone, the path planned round the
//! obstacles stereo ranged. Judged from the recording against the simulator's truth: the goal is
//! reached and nothing in the room is ever touched; the model ends within 0.25 m of the truth
//! (the paper: under half a metre) and no step is off by 0.15 m (the paper: drastic errors near
//! a metre; over 20 seeds the worst step was 0.124 m, under harsh). Issue 18's bars (0.10 m at
//! the end, 0.05 m a step) are not met on every seed: `docs/evaluation.md` has the sweep.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use common::truth::Truth;
use harvey_msgs::{BehaviourState, Pose2};

/// What a run's recording says of it.
#[derive(Debug)]
struct Figures {
    /// The position model's distance from the truth at the end (m).
    final_error_m: f64,
    /// The true robot's distance from the goal at the end (m).
    from_goal_m: f64,
    /// Stops, the worst step error (m), and stops whose motion came from the encoders.
    stops: usize,
    worst_step_m: f64,
    unsolved: u32,
    /// The nearest the robot's edge came to any wall or piece of furniture (m).
    clearance_m: f64,
}

fn distance_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

fn figures(mcap: &[u8]) -> Figures {
    let world = harvey_world::load_str(include_str!("../worlds/room.toml"), "room").expect("world");
    let mut truth = Truth::default();
    let mut looks: Vec<(u64, Pose2)> = Vec::new();
    let mut last: Option<BehaviourState> = None;
    for m in mcap::MessageStream::new(mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            Truth::TOPIC => truth.push(&m),
            "/executive/behaviour" => {
                let b = harvey_cdr::decode::<BehaviourState>(&m.data).expect("state");
                // The model as each look left it (a look answered counts a stop).
                if last.is_none_or(|l| l.transitions != b.transitions) {
                    looks.push((b.header.stamp_ns, b.at));
                }
                last = Some(b);
            }
            _ => {}
        }
    }
    let last = last.expect("behaviour states");
    let end = truth.last();
    let steps: Vec<f64> = looks
        .windows(2)
        .map(|w| {
            let model = w[0].1.relative(&w[1].1);
            let true_step = truth.at(w[0].0).relative(&truth.at(w[1].0));
            (model.x_m - true_step.x_m).hypot(model.y_m - true_step.y_m)
        })
        .collect();
    let radius = world.robot.sonar_ring_radius_m;
    let clearance = truth
        .0
        .iter()
        .flat_map(|(_, p)| world.walls.iter().map(move |w| distance_to_segment([p.x_m, p.y_m], w.from, w.to)))
        .fold(f64::INFINITY, f64::min)
        - radius;
    Figures {
        final_error_m: (last.at.x_m - end.x_m).hypot(last.at.y_m - end.y_m),
        from_goal_m: (end.x_m - 7.2).hypot(end.y_m - 3.0),
        stops: looks.len(),
        worst_step_m: steps.iter().copied().fold(0.0, f64::max),
        unsolved: last.transitions - last.achieved,
        clearance_m: clearance,
    }
}

fn check(condition: &str, seeds: std::ops::RangeInclusive<u64>) {
    for seed in seeds {
        let out = common::run_mission_under("missions/neptune.toml", condition, seed, "neptune");
        assert!(
            out.status.success() && out.stdout.contains("goal reached"),
            "{condition} s{seed}: {}",
            out.stdout
        );
        let f = figures(&out.mcap);
        println!("{condition} s{seed}: {f:?}");
        assert!(f.final_error_m < 0.25, "{condition} s{seed}: the model ends {:.3} m off", f.final_error_m);
        assert!(f.from_goal_m < 0.35, "{condition} s{seed}: {:.3} m from the goal", f.from_goal_m);
        assert!(f.worst_step_m < 0.15, "{condition} s{seed}: a step off by {:.3} m", f.worst_step_m);
        assert!(f.clearance_m > 0.0, "{condition} s{seed}: touched something ({:.3} m)", f.clearance_m);
        assert!(f.stops >= 16, "{condition} s{seed}: {} stops for 6.4 m of 0.4 m steps", f.stops);
        // Most stops are solved by stereo; those that are not are dead reckoned and counted.
        assert!(
            f.unsolved * 3 <= f.stops as u32,
            "{condition} s{seed}: {} of {} stops unsolved",
            f.unsolved,
            f.stops
        );
    }
}

#[test]
fn neptune_crosses_the_lab_by_stereo_alone() {
    check("nominal", 1..=3);
}

#[test]
fn neptune_crosses_the_lab_by_stereo_alone_on_a_dim_day() {
    check("dim", 1..=2);
}

#[test]
fn neptune_crosses_the_lab_by_stereo_alone_on_a_harsh_day() {
    check("harsh", 1..=2);
}
