//! 000 §5.5, Fig. 11 as missions: the straight run down the hallway in 2 ft increments. Servoed
//! on the exit sign after each increment, the robot stays within 0.3 in of the line over 40 ft;
//! open loop (002 Table 3's drift), it is over 2 in off by 18-20 ft. With a cart coming at it, the
//! panic-avoid evades and the servoed run, resumed where its increment began, regains the line.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_geometry::{FT, INCH};
use harvey_msgs::{
    CommandKind, MissionStatus, MotionCommand, ServoCorrection, ServoLevel, TruePose, VisionResult,
    VisionStatus,
};

/// What a run recorded: the true poses (x, y along and across the line, which is the x axis),
/// the executive's correlation results, its corrections, and the servo levels it reported.
struct Run {
    truth: Vec<[f64; 2]>,
    looks: Vec<VisionResult>,
    corrections: Vec<ServoCorrection>,
    levels: Vec<u32>,
    /// The reflexes' commands.
    reflexes: Vec<MotionCommand>,
}

fn run(mission: &str, tag: &str, steps: &str) -> Run {
    decode(common::run_mission(mission, tag), mission, steps)
}

/// A run's recording, once it is checked to have reached the goal after `steps`.
fn decode(out: common::MissionRun, mission: &str, steps: &str) -> Run {
    assert!(
        out.status.success() && out.stdout.contains(&format!("goal reached ({steps} steps)")),
        "{mission}: {}\n{}",
        out.stdout,
        out.stderr
    );
    let bytes = out.mcap.as_slice();
    let (mut truth, mut looks, mut corrections, mut levels, mut reflexes) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for m in mcap::MessageStream::new(bytes).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/sim/truth" => {
                let p = harvey_cdr::decode::<TruePose>(&m.data).expect("truth").world_from_robot;
                truth.push([p.x_m, p.y_m]);
            }
            "/executive/servo" => {
                corrections.push(harvey_cdr::decode::<ServoCorrection>(&m.data).expect("correction"))
            }
            "/executive/status" => {
                levels.push(harvey_cdr::decode::<MissionStatus>(&m.data).expect("status").servo)
            }
            "/vehicle/reflex" => reflexes.push(harvey_cdr::decode::<MotionCommand>(&m.data).expect("reflex")),
            "/vision/results" => {
                let r = harvey_cdr::decode::<VisionResult>(&m.data).expect("result");
                if r.request_id >= 100 {
                    looks.push(r);
                }
            }
            _ => {}
        }
    }
    Run { truth, looks, corrections, levels, reflexes }
}

/// The largest offset from the line over the stretch `from_ft ..= to_ft` of it.
fn worst(truth: &[[f64; 2]], from_ft: f64, to_ft: f64) -> f64 {
    truth
        .iter()
        .filter(|p| (from_ft * FT..=to_ft * FT).contains(&p[0]))
        .map(|p| p[1].abs())
        .fold(0.0, f64::max)
}

#[test]
fn servoing_holds_the_line_for_40_ft_where_open_loop_wanders_off_it() {
    let Run { truth: servoed, looks, corrections, levels, .. } =
        run("missions/hallway-40ft.toml", "h40", "1/1");
    let travelled = servoed.last().expect("truth")[0];
    let held = worst(&servoed, 0.0, 40.0);
    println!("servoed: {:.2} ft travelled, at most {:.3} in off the line", travelled / FT, held / INCH);
    // 40 ft commanded; tile's translational loss (002 Table 3, 4.2 %) leaves it about 38 ft.
    assert!(travelled > 37.5 * FT, "{} ft", travelled / FT);
    // 000 Fig. 11: within 0.3 in, on an exact map. The shipped hallway is built 1 cm (sd) off its
    // map (`[map_error]`), and the robot measures its mount's misalignment against the sign's
    // mapped place, so the line it holds is itself off by up to 1 cm x 12 m / 17 m = 0.28 in
    // (1 sd): the bound is the paper's plus that.
    assert!(held <= 0.58 * INCH, "servoed: {} in off the line", held / INCH);
    // A look before the first increment (the mount's boresight) and after each of the 20, each
    // finding the sign.
    assert_eq!(looks.len(), 21);
    assert!(looks.iter().all(|r| r.status == VisionStatus::Found as u32 && r.items[0].values[2] >= 0.9));
    // Each look's correction is published (and drawn in run.rrd), after increments 1 to 20;
    // the drift of an increment is well under 2 degrees.
    assert_eq!(corrections.iter().map(|c| c.increment).collect::<Vec<_>>(), (1..=20).collect::<Vec<_>>());
    assert!(corrections.iter().all(|c| c.heading_error_rad.abs() < 2f64.to_radians()), "{corrections:?}");
    assert!(levels.contains(&(ServoLevel::Action as u32)), "action-level servoing reported");

    let Run { truth: open, looks, corrections, levels, .. } =
        run("missions/hallway-40ft-open.toml", "h40open", "1/1");
    assert!(corrections.is_empty() && levels.iter().all(|&l| l == ServoLevel::None as u32));
    let at_18_20 = worst(&open, 18.0, 20.0);
    println!("open loop: {:.3} in off the line at 18-20 ft", at_18_20 / INCH);
    assert!(looks.is_empty(), "open loop looks at nothing");
    assert!(at_18_20 > 2.0 * INCH, "open loop: {} in at 18-20 ft", at_18_20 / INCH);
    // Over the same stretch the servoed run is many times closer.
    assert!(worst(&servoed, 0.0, 20.0) * 10.0 < at_18_20);
}

#[test]
fn over_seeds_servoing_holds_the_line_within_its_budget() {
    for condition in ["ideal", "nominal", "harsh"] {
        // Harsh seed 13 too: searched over the whole frame, its first look took the hall's
        // corner for the exit sign's, measured the mount 127 px off, and the run failed.
        let extra = (condition == "harsh").then_some(13);
        for seed in (1..=3).chain(extra) {
            let out = common::run_mission_under("missions/hallway-40ft.toml", condition, seed, "h40s");
            let Run { truth, looks, .. } = decode(out, "missions/hallway-40ft.toml", "1/1");
            let held = worst(&truth, 0.0, 40.0) / INCH;
            println!("{condition} s{seed}: at most {held:.3} in off the line");
            // The paper's 0.3 in where the map is the world; its 0.3 in plus the map's 0.28 in
            // (above) under the shipped sensors; under harsh, whose map is twice as far off (2 cm
            // sd), twice that. Harsh seed 2 left the line by 16 in while the looks searched the
            // whole frame (another surface's match, refused, every look after it).
            let bound = match condition {
                "ideal" => 0.3,
                "nominal" => 0.58,
                _ => 0.3 + 2.0 * 0.28,
            };
            assert!(held <= bound, "{condition} s{seed}: {held:.3} in off the line");
            assert_eq!(looks.len(), 21, "{condition} s{seed}");
        }
    }
}

#[test]
fn after_evading_a_cart_the_servoed_run_regains_the_line() {
    for (condition, seed) in [("nominal", 1), ("nominal", 2), ("harsh", 1)] {
        let mission = "missions/hallway-40ft-cart.toml";
        let out = common::run_mission_under(mission, condition, seed, "h40cart");
        let Run { truth, looks, reflexes, .. } = decode(out, mission, "1/1");
        // The panic-avoid turned the robot aside (a right angle) about 4 m in.
        let turn = reflexes.iter().find(|c| c.kind == CommandKind::Turn as u32).expect("an evasion");
        assert!((turn.angle_rad.abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-9, "{turn:?}");
        let (late, end) = (worst(&truth, 20.0, 40.0) / INCH, truth.last().expect("truth")[1].abs() / INCH);
        println!(
            "{condition} s{seed}: {} looks, over the last 20 ft at most {late:.2} in off the line, {end:.2} in at the end",
            looks.len()
        );
        // Back where the increment began and servoing again, a look after every increment.
        // Servoing on a sign at the hall's end measures the heading, not the offset from the
        // line: what the return by odometry left (the evasion's turns cost heading) stays. Over
        // seeds 1..8 under nominal, dim and harsh (24 runs, all reaching the goal) the last
        // 20 ft held within 1.0-2.4 in of the line (median 1.9), 0.3-1.5 in at the end; the
        // undisturbed run holds 0.3-0.9 in.
        assert!(looks.len() >= 21, "{condition} s{seed}: {} looks", looks.len());
        assert!(late <= 3.0, "{condition} s{seed}: {late:.2} in off the line over the last 20 ft");
        assert!(end <= 2.0, "{condition} s{seed}: {end:.2} in off the line at the end");
    }
}
