//! 001 §6.2, panic-avoid, as a mission: a cart rolls up the hall at the robot driving down it.
//! The sonar's reflex stops the robot, turns it a right angle away from the cart and dashes it
//! aside, holds it still while the cart goes by, and the executive then gets back to its goal.
//! With the reflex turned off (the control), the panic-stop freezes the robot in the cart's way
//! and the cart would hit it.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_msgs::{CommandKind, MotionCommand, PANIC_STOP_IDS, REFLEX_ID_BIT, TruePose};
use harvey_world::{Mover, parse_movers};

/// The robot's radius (its sonar ring, `worlds/hallway.toml`).
const RADIUS_M: f64 = 0.23;

struct Run {
    reached: bool,
    /// Closest distance from the robot's centre to the cart's footprint.
    closest_m: f64,
    /// The panic-avoid's commands, and how many panic-stops were sent.
    reflex: Vec<MotionCommand>,
    panic_stops: usize,
}

fn distance_to(cart: &Mover, t_s: f64, p: [f64; 2]) -> f64 {
    let c = cart.at(t_s);
    let (hx, hy) =
        cart.outline.iter().fold((0.0f64, 0.0f64), |(x, y), v| (x.max(v[0].abs()), y.max(v[1].abs())));
    let (dx, dy) = (((p[0] - c[0]).abs() - hx).max(0.0), ((p[1] - c[1]).abs() - hy).max(0.0));
    dx.hypot(dy)
}

fn run(launch: &std::path::Path, tag: &str) -> Run {
    let text = std::fs::read_to_string(launch).expect("launch file");
    let movers = parse_movers(&text, "panic-avoid").expect("movers");
    let cart = movers.first().expect("a cart");
    let out = common::run_mission(launch.to_str().expect("utf8"), tag);
    let bytes = out.mcap.as_slice();
    let (mut closest_m, mut reflex, mut panic_stops) = (f64::MAX, Vec::new(), 0);
    for m in mcap::MessageStream::new(bytes).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/sim/truth" => {
                let t = harvey_cdr::decode::<TruePose>(&m.data).expect("truth");
                let p = t.world_from_robot;
                closest_m = closest_m.min(distance_to(cart, t.header.stamp_ns as f64 * 1e-9, [p.x_m, p.y_m]));
            }
            "/vehicle/reflex" => {
                let c = harvey_cdr::decode::<MotionCommand>(&m.data).expect("command");
                match c.command_id & PANIC_STOP_IDS {
                    PANIC_STOP_IDS => panic_stops += 1,
                    REFLEX_ID_BIT => reflex.push(c),
                    _ => panic!("a reflex command without a reflex id: {c:?}"),
                }
            }
            _ => {}
        }
    }
    Run {
        reached: out.status.success() && out.stdout.contains("goal reached (1/1 steps)"),
        closest_m,
        reflex,
        panic_stops,
    }
}

#[test]
fn the_robot_gets_out_of_the_carts_way_and_then_to_its_goal() {
    let mission = common::repo().join("missions/panic-avoid.toml");
    let evading = run(&mission, "pavoid");
    println!(
        "with panic-avoid: closest {:.3} m, {} reflex commands",
        evading.closest_m,
        evading.reflex.len()
    );
    assert!(evading.reached, "the executive gets back to its goal after the reflex");
    assert!(evading.closest_m > RADIUS_M + 0.15, "closest {} m", evading.closest_m);
    // Stop, a right angle left (the cart comes on the right), a dash, then stops while it passes.
    let kinds: Vec<u32> = evading.reflex.iter().map(|c| c.kind).collect();
    assert_eq!(kinds[..3], [CommandKind::Stop as u32, CommandKind::Turn as u32, CommandKind::Move as u32]);
    assert!((evading.reflex[1].angle_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
    assert!(evading.reflex[2].distance_m > 0.3 && evading.reflex[2].distance_m <= 1.5 * 0.3048 + 1e-9);
    assert!(evading.reflex.iter().all(|c| c.urgent == 1));

    // The control: the same run with the reflex off.
    let text = std::fs::read_to_string(&mission).expect("mission");
    let worlds = common::repo().join("worlds");
    let off = text
        .replace("\"--avoid-dash-ft\", \"1.5\"", "\"--avoid-dash-ft\", \"0\"")
        .replace("../worlds", worlds.to_str().expect("utf8"));
    assert_ne!(off, text);
    let dir = common::scratch("pavoid-off-launch");
    let control = dir.join("panic-avoid-off.toml");
    std::fs::write(&control, off).expect("control launch file");
    let frozen = run(&control, "pavoid-off");
    println!("without: closest {:.3} m", frozen.closest_m);
    assert!(frozen.reflex.is_empty() && frozen.panic_stops > 0, "only the panic-stop acts");
    // Frozen in the cart's way, the robot would be hit (the simulator lets the cart pass through;
    // the executive then carries on once the panic-stop lets go).
    assert!(frozen.closest_m < RADIUS_M, "the cart would hit the robot: {} m", frozen.closest_m);
}
