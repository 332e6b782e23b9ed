//! The Expecter on the simulated robot in the hallway: over 500 seeded runs, the windows it
//! predicts from the grown map contain each active landmark's true image position in at least
//! 99 % of sightings, and are smaller than the windows of a disk model of the same uncertainty
//! (002 Fig. 69).

use harvey_drv_protocol::Command;
use harvey_sim_drv::SimDrv;
use harvey_ums::expecter::{View, disk_window, feature_points, window};
use harvey_ums::map::{Growth, Map};

#[test]
fn windows_contain_the_truth_and_beat_the_disk_model() {
    let world =
        harvey_world::load_str(include_str!("../../worlds/hallway.toml"), "hallway").expect("hallway");
    let view = View { camera: &world.camera, width_px: 640, height_px: 480 };
    let (mut sightings, mut inside, mut ratio_sum, mut ratios) = (0u32, 0u32, 0.0, 0u32);
    for seed in 0..500 {
        let mut sim = SimDrv::new(world.clone(), 1000, seed);
        let s = world.start;
        let mut map = Map::exact(s.x_m, s.y_m, s.heading_rad);
        for (i, (deg, ft)) in [(0.0, 8.0), (8.0, 6.0), (-8.0, 6.0)].iter().enumerate() {
            let id = 2 * i as u32 + 1;
            for cmd in [
                Command::Turn { id, tenths_deg: (deg * 10.0) as i32 },
                Command::Move { id: id + 1, hundredths_ft: (ft * 100.0) as i32 },
            ] {
                sim.handle(cmd);
                while sim.is_moving() {
                    sim.tick();
                }
            }
            let terrain = world.terrain_at(map.centre[0], map.centre[1]);
            let g = Growth { terrain, sigmas: 3.0 };
            g.turn(&mut map, f64::to_radians(*deg));
            g.run(&mut map, ft * 0.3048, true);
        }
        let t = sim.truth();
        for l in world.landmarks.iter().filter(|l| l.active_from(t.x_m, t.y_m, t.heading_rad.to_degrees())) {
            let Some(win) = window(&map, view, l, 0.0) else { continue };
            // Where the landmark really is in the image, seen from the true pose.
            let truth: Vec<[f64; 2]> = feature_points(l, [t.x_m, t.y_m], l.activation_range_m)
                .iter()
                .filter_map(|x| world.camera.project(640, 480, t, *x))
                .filter(|[u, v]| (0.0..640.0).contains(u) && (0.0..480.0).contains(v))
                .collect();
            if truth.is_empty() {
                continue;
            }
            sightings += 1;
            inside += u32::from(truth.iter().all(|p| win.contains(*p)));
            if let Some(disk) = disk_window(&map, view, l, 0.0) {
                ratio_sum += win.area_px() / disk.area_px();
                ratios += 1;
            }
        }
    }
    let rate = f64::from(inside) / f64::from(sightings);
    let ratio = ratio_sum / f64::from(ratios);
    println!(
        "{sightings} sightings: truth inside the window in {rate:.4}; polygon / disk window area = {ratio:.3}"
    );
    assert!(sightings > 1000, "{sightings}");
    assert!(rate >= 0.99, "{rate}");
    assert!(ratio < 1.0, "{ratio}");
}
