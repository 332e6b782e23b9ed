//! The map's promise, measured on the simulated robot: over 500 seeded runs of turn-and-run
//! legs on each terrain, the true pose ends inside the polygon and the true heading inside the
//! wedge at least as often as the map's probability (3 sigma) says.

use harvey_drv_protocol::Command;
use harvey_sim_drv::SimDrv;
use harvey_ums::map::{Growth, Map};
use harvey_world::World;

const RUNS: u64 = 500;

fn campus_on(terrain: &str) -> World {
    let mut w =
        harvey_world::load_str(include_str!("../../worlds/campus.toml"), "campus.toml").expect("campus");
    assert!(w.start_on_terrain(terrain), "a meadow of {terrain}");
    w
}

fn execute(sim: &mut SimDrv, cmd: Command) {
    sim.handle(cmd);
    while sim.is_moving() {
        sim.tick();
    }
}

#[test]
fn the_truth_stays_inside_the_map_at_its_probability() {
    // (turn degrees, run feet) legs: a dog-leg that stays on each meadow.
    let legs = [(30.0, 8.0), (-45.0, 6.0), (10.0, 4.0)];
    let base =
        harvey_world::load_str(include_str!("../../worlds/campus.toml"), "campus.toml").expect("campus");
    for (name, terrain) in &base.terrain {
        let world = campus_on(name);
        let growth = Growth { terrain, sigmas: 3.0 };
        let (mut inside_pos, mut inside_heading, mut inside_both) = (0, 0, 0);
        let mut area = 0.0;
        for seed in 0..RUNS {
            let mut sim = SimDrv::new(world.clone(), 1000, seed);
            let s = world.start;
            let mut map = Map::exact(s.x_m, s.y_m, s.heading_rad);
            for (i, (deg, ft)) in legs.iter().enumerate() {
                let id = 2 * i as u32 + 1;
                execute(&mut sim, Command::Turn { id, tenths_deg: (deg * 10.0) as i32 });
                execute(&mut sim, Command::Move { id: id + 1, hundredths_ft: (ft * 100.0) as i32 });
                growth.turn(&mut map, f64::to_radians(*deg));
                growth.run(&mut map, ft * 0.3048, true);
            }
            let t = sim.truth();
            let pos = harvey_ums::geometry::contains(&map.polygon, [t.x_m, t.y_m], 1e-9);
            let head = map.contains(map.centre, t.heading_rad, 0.0);
            inside_pos += u32::from(pos);
            inside_heading += u32::from(head);
            inside_both += u32::from(pos && head);
            area = map.area_m2();
        }
        let rate = |n: u32| f64::from(n) / RUNS as f64;
        println!(
            "{name:<10} position inside {:.3}  heading inside {:.3}  both {:.3}  (area {:.4} m^2)",
            rate(inside_pos),
            rate(inside_heading),
            rate(inside_both),
            area
        );
        assert!(
            rate(inside_both) >= 0.99,
            "{name}: truth inside the 3-sigma map in only {:.3} of runs",
            rate(inside_both)
        );
    }
}
