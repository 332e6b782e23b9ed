//! The simulated DRV's motion errors against AuRA's Table 3 (002 §3.2): over 1000 seeded MOVEs
//! and 1000 seeded TURNs on each terrain, the measured means and standard deviations of
//! translational loss, drift, rotational loss and skitter match the table within sampling
//! tolerance. The vehicle never goes further than commanded.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_drv_protocol::Command;
use harvey_sim_drv::SimDrv;
use harvey_sim_drv::motion::{FT, Pose2};
use harvey_world::{Terrain, World};

const RUNS: u64 = 1000;

/// The campus with the robot starting in the middle of a meadow of `terrain`: the simulator
/// takes the terrain from the meadow under the robot.
fn campus_on(terrain: &str) -> World {
    let mut w =
        harvey_world::load_str(include_str!("../../../worlds/campus.toml"), "campus.toml").expect("campus");
    assert!(w.start_on_terrain(terrain), "a meadow of {terrain}");
    w
}

fn run(world: &World, seed: u64, cmd: Command) -> Pose2 {
    let mut sim = SimDrv::new(world.clone(), 1000, seed);
    sim.handle(cmd);
    for _ in 0..1000 {
        sim.tick();
        if !sim.is_moving() {
            return sim.truth();
        }
    }
    panic!("motion never finished");
}

fn mean_sd(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    (mean, (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
}

/// Checks a sample's mean within 4 standard errors and its deviation within 10 % (the standard
/// error of a deviation over 1000 samples is about 2.2 %).
fn check(what: &str, xs: &[f64], mean: f64, sd: f64) {
    let (m, s) = mean_sd(xs);
    let se = sd / (xs.len() as f64).sqrt();
    assert!((m - mean).abs() <= 4.0 * se, "{what}: mean {m:.6} vs {mean:.6} (4 SE = {:.6})", 4.0 * se);
    assert!((s - sd).abs() <= 0.1 * sd, "{what}: sd {s:.6} vs {sd:.6}");
    println!("{what:<40} mean {m:>9.6} (table {mean:>9.6})  sd {s:>9.6} (table {sd:>9.6})");
}

fn moves(t: &Terrain, world: &World, name: &str) {
    let ft = 10.0;
    let (mut loss, mut drift) = (Vec::new(), Vec::new());
    for seed in 0..RUNS {
        let p = run(world, seed, Command::Move { id: 1, hundredths_ft: (ft * 100.0) as i32 });
        let chord_ft = (p.x_m - world.start.x_m).hypot(p.y_m - world.start.y_m) / FT;
        let th = p.heading_rad.abs();
        // Arc length from the chord and the heading change the drift made.
        let arc_ft = if th > 1e-12 { chord_ft * (th / 2.0) / (th / 2.0).sin() } else { chord_ft };
        assert!(arc_ft <= ft + 1e-9, "{name}: seed {seed} went {arc_ft} ft for {ft}");
        loss.push((ft - arc_ft) / ft);
        drift.push(th.to_degrees() / arc_ft);
    }
    // Per-foot loss: the distance loss plus the inertial loss spread over the 10 ft.
    check(
        &format!("{name} translational loss (ft/ft)"),
        &loss,
        t.translational_loss_ft_per_ft + t.inertial_loss_ft / ft,
        t.translational_sd_ft_per_ft,
    );
    check(&format!("{name} drift (deg/ft)"), &drift, t.drift_deg_per_ft, t.drift_sd_deg_per_ft);
}

fn turns(t: &Terrain, world: &World, name: &str) {
    let deg = 90.0;
    let (mut loss, mut skitter) = (Vec::new(), Vec::new());
    for seed in 0..RUNS {
        let p = run(world, seed, Command::Turn { id: 1, tenths_deg: (deg * 10.0) as i32 });
        let turned = p.heading_rad.to_degrees();
        assert!((0.0..=deg).contains(&turned), "{name}: seed {seed} turned {turned} for {deg}");
        loss.push((deg - turned) / deg);
        skitter.push((p.x_m - world.start.x_m).hypot(p.y_m - world.start.y_m) / FT / deg);
    }
    check(
        &format!("{name} rotational loss (deg/deg)"),
        &loss,
        t.rotational_loss_deg_per_deg,
        t.rotational_sd_deg_per_deg,
    );
    check(&format!("{name} skitter (ft/deg)"), &skitter, t.skitter_ft_per_deg, t.skitter_sd_ft_per_deg);
}

#[test]
fn motion_errors_match_table_3_on_every_terrain() {
    let base =
        harvey_world::load_str(include_str!("../../../worlds/campus.toml"), "campus.toml").expect("campus");
    for (name, t) in &base.terrain {
        let world = campus_on(name);
        moves(t, &world, name);
        turns(t, &world, name);
    }
}
