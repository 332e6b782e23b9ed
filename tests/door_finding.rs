//! Door finding by sonar alone (001 §3.2) as missions, both of the paper's ways: following the
//! wall (`missions/door-finding.toml`) and motor schemas (`missions/door-finding-schemas.toml`).
//! Each is swept over 20 seeds under the nominal ring and the harsh one (twice the range noise,
//! 5 % dropouts, crosstalk and multipath; the map 2 cm off), and judged from each recording
//! against the simulator's truth: the robot ends in the lab, past the doorway, having touched
//! nothing; where its centre crossed the doorway's line (against the doorway's middle) and how
//! near it came to the jambs are the figures, printed as a table with their median and worst.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_msgs::{Pose2, TruePose};

/// What a run's recording says of it.
#[derive(Debug, Clone, Copy)]
struct Figures {
    /// How far into the lab the robot's centre ended, past the doorway's line (m).
    past_m: f64,
    /// Where the centre crossed the doorway's line, from its middle along the wall (m).
    crossing_m: f64,
    /// The nearest the robot's edge came to a jamb (m), and to any wall (m).
    jamb_m: f64,
    wall_m: f64,
}

fn distance_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

/// The figures of a run whose world is the hallway, with the lab's doorway (the world's first).
fn figures(mcap: &[u8]) -> Figures {
    let world = harvey_world::load_str(include_str!("../worlds/hallway.toml"), "hallway").expect("world");
    let door = &world.doors[0];
    let (mid, half) = (door.at, door.width_m / 2.0);
    let jambs = [[mid[0] - half, mid[1]], [mid[0] + half, mid[1]]];
    let mut truth: Vec<Pose2> = Vec::new();
    for m in mcap::MessageStream::new(mcap).expect("mcap") {
        let m = m.expect("message");
        if m.channel.topic == "/sim/truth" {
            truth.push(harvey_cdr::decode::<TruePose>(&m.data).expect("truth").world_from_robot);
        }
    }
    let radius = world.robot.sonar_ring_radius_m;
    let near = |f: &dyn Fn(&Pose2) -> f64| truth.iter().map(f).fold(f64::INFINITY, f64::min) - radius;
    let jamb_m =
        near(&|p| jambs.iter().map(|j| (p.x_m - j[0]).hypot(p.y_m - j[1])).fold(f64::INFINITY, f64::min));
    let wall_m = near(&|p| {
        world
            .walls
            .iter()
            .map(|w| distance_to_segment([p.x_m, p.y_m], w.from, w.to))
            .fold(f64::INFINITY, f64::min)
    });
    // The doorway's line is y = mid[1] (the hallway's north wall); the lab lies beyond it.
    let crossing = truth.windows(2).find(|w| w[0].y_m < mid[1] && w[1].y_m >= mid[1]);
    let crossing_m = crossing.map_or(f64::INFINITY, |w| {
        let t = (mid[1] - w[0].y_m) / (w[1].y_m - w[0].y_m);
        w[0].x_m + t * (w[1].x_m - w[0].x_m) - mid[0]
    });
    let end = truth.last().expect("truth");
    Figures { past_m: end.y_m - mid[1], crossing_m, jamb_m, wall_m }
}

fn median_worst(v: &mut [f64], worst_is_low: bool) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], if worst_is_low { v[0] } else { v[v.len() - 1] })
}

/// How near the doorway's middle a mission must cross, and how far from the jambs it must keep
/// (m), on every run.
struct Bars {
    crossing_m: f64,
    jamb_m: f64,
}

/// Sweeps `mission` over seeds 1..=20, nominal and harsh; checks every run and prints the table.
fn sweep(mission: &str, tag: &str, bars: &Bars) {
    let (prefix, out) = (common::unique_prefix(tag), common::scratch(tag));
    let args = ["sweep", mission, "--seeds", "1..20", "--conditions", "nominal,harsh", "--in-process"];
    let run = common::harvey(&args)
        .args(["--jobs", "2", "--keep", "--out", out.to_str().expect("utf8"), "--prefix", &prefix])
        .output()
        .expect("runs");
    // The sweep exits non-zero when a run fails; its runs are judged here, each from its recording.
    assert!(out.join("sweep.csv").exists(), "{}", String::from_utf8_lossy(&run.stderr));
    let mut misses = Vec::new();
    for condition in ["nominal", "harsh"] {
        let mut rows = Vec::new();
        for seed in 1..=20 {
            let dir = out.join("runs").join(format!("{condition}-s{seed}"));
            let log = std::fs::read_to_string(dir.join("harvey-run.log")).unwrap_or_default();
            let f = figures(&std::fs::read(dir.join("run.mcap")).expect("recording"));
            let through = log.contains("goal reached") && f.past_m > 0.5 && f.wall_m > 0.0;
            println!(
                "{condition} s{seed}: {} past {:.2} m, crossed {:+.3} m from the middle, jambs {:.3} m, walls {:.3} m",
                if through { "through," } else { "MISSED," },
                f.past_m,
                f.crossing_m,
                f.jamb_m,
                f.wall_m
            );
            if !through {
                misses.push(format!("{condition} s{seed}"));
            }
            rows.push(f);
        }
        let (c_med, c_worst) =
            median_worst(&mut rows.iter().map(|f| f.crossing_m.abs()).collect::<Vec<_>>(), false);
        let (j_med, j_worst) = median_worst(&mut rows.iter().map(|f| f.jamb_m).collect::<Vec<_>>(), true);
        println!(
            "{mission} {condition}: crossing off the middle median {c_med:.3} worst {c_worst:.3} m; \
             jamb clearance median {j_med:.3} worst {j_worst:.3} m"
        );
        if c_worst >= bars.crossing_m || j_worst <= bars.jamb_m {
            misses.push(format!(
                "{condition}: crossed up to {c_worst:.3} m off the middle, {j_worst:.3} m from a jamb"
            ));
        }
    }
    assert!(misses.is_empty(), "{mission}: {misses:?}");
}

// A 0.9 m doorway leaves a 0.46 m robot 0.22 m a side. Following the wall puts it through the
// middle (over seeds 1..40 the worst crossing was 0.068 m off, the nearest jamb 0.152 m away);
// the schemas come in at a slant, carried along the wall until the press wins, so they cross
// further along (worst 0.160 m, nearest jamb 0.051 m; docs/evaluation.md).

#[test]
fn following_the_wall_finds_the_doorway_and_goes_through_on_every_seed() {
    sweep("missions/door-finding.toml", "doorwf", &Bars { crossing_m: 0.10, jamb_m: 0.12 });
}

#[test]
fn motor_schemas_find_the_doorway_and_go_through_on_every_seed() {
    sweep("missions/door-finding-schemas.toml", "doorsc", &Bars { crossing_m: 0.20, jamb_m: 0.03 });
}

#[test]
fn a_door_finding_run_replays_identically_as_processes() {
    common::assert_replays("missions/door-finding.toml", "doorrp", &[]);
}

#[test]
fn a_schemas_door_finding_run_replays_identically_in_process() {
    common::assert_replays("missions/door-finding-schemas.toml", "doorri", &["--in-process"]);
}
