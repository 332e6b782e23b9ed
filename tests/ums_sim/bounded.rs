//! 002 Fig. 79 against Fig. 80 on the simulated robot in the hallway: without landmarks the map
//! grows without bound along 40 ft of corridor; with sightings after every leg of the landmarks
//! the camera would see (door jambs as class I lines, the exit sign as a class II point, the
//! baseboard as a class III ground line) it stays bounded and the truth stays inside. The sightings here are the true geometry plus seeded
//! noise within the stated errors: a stand-in for the vision workers' measurements.

use harvey_drv_protocol::Command;
use harvey_sim_drv::SimDrv;
use harvey_ums::map::{Growth, Map, wrap};
use harvey_ums::reduction::{Known, Observation, apply};
use harvey_world::LandmarkClass;

struct Noise(u64);
impl Noise {
    /// Uniform in [-sd, sd].
    fn within(&mut self, sd: f64) -> f64 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * sd
    }
}

fn run(with_landmarks: bool, seed: u64) -> Vec<f64> {
    let world =
        harvey_world::load_str(include_str!("../../worlds/hallway.toml"), "hallway").expect("hallway");
    let terrain = world.terrain["tile"].clone();
    let growth = Growth { terrain: &terrain, sigmas: 3.0 };
    // Bearing error of one vision measurement: about two pixels.
    let sd_b = 2.0 / world.camera.focal_px;
    let mut sim = SimDrv::new(world.clone(), 1000, seed);
    let mut map = Map::exact(0.0, 0.0, 0.0);
    let mut noise = Noise(seed + 1);
    let mut areas = Vec::new();
    for leg in 0..20u32 {
        // Two feet at a time, as action-level servoing would move (000 §5.5).
        sim.handle(Command::Move { id: leg + 1, hundredths_ft: 200 });
        while sim.is_moving() {
            sim.tick();
        }
        growth.run(&mut map, 2.0 * 0.3048, true);
        let t = sim.truth();
        if with_landmarks {
            for l in
                world.landmarks.iter().filter(|l| l.active_from(t.x_m, t.y_m, t.heading_rad.to_degrees()))
            {
                let c = [l.position_m[0], l.position_m[1]];
                let known = Known { at: c, to: l.to_m.map(|p| [p[0], p[1]]), position_sd_m: 0.0 };
                let bearing = wrap((c[1] - t.y_m).atan2(c[0] - t.x_m) - t.heading_rad);
                let range = (c[0] - t.x_m).hypot(c[1] - t.y_m);
                let obs = match l.class {
                    LandmarkClass::III => {
                        // The baseboard runs along +x at y = 1: the robot is (1 - y) to its right.
                        let (sd_h, sd_o) = (0.01, 0.02);
                        Observation::GroundLine {
                            heading_rad: wrap(t.heading_rad) + noise.within(sd_h),
                            heading_sd_rad: sd_h,
                            offset_m: t.y_m - 1.0 + noise.within(sd_o),
                            offset_sd_m: sd_o,
                        }
                    }
                    // Only what the camera sees: ahead, within its 60 degree field of view.
                    _ if bearing.abs() > 30f64.to_radians() => continue,
                    LandmarkClass::I => {
                        Observation::Bearing { bearing_rad: bearing + noise.within(sd_b), sd_rad: sd_b }
                    }
                    LandmarkClass::II => {
                        // Depth from a point of known height: one pixel of row error at range d
                        // is d^2 / (f dh) metres.
                        let dh = (l.position_m[2] - world.camera.height_m).abs().max(0.1);
                        let sd_r = range * range / (world.camera.focal_px * dh);
                        Observation::BearingRange {
                            bearing_rad: bearing + noise.within(sd_b),
                            sd_rad: sd_b,
                            range_m: range + noise.within(sd_r),
                            range_sd_m: sd_r,
                        }
                    }
                };
                map = apply(&map, &known, &obs, 3.0)
                    .unwrap_or_else(|e| panic!("leg {leg}: {} consistent with the truth, yet {e}", l.name));
            }
        }
        assert!(map.contains([t.x_m, t.y_m], t.heading_rad, 1e-9), "leg {leg}: truth outside the map");
        areas.push(map.area_m2());
    }
    areas
}

#[test]
fn landmarks_keep_the_map_bounded_where_dead_reckoning_lets_it_grow() {
    let mut ratios = Vec::new();
    for seed in 0..20 {
        let open = run(false, seed);
        let held = run(true, seed);
        assert!(open.windows(2).all(|w| w[1] > w[0]), "without landmarks the area only grows");
        assert!(
            open[19] > 4.0 * open[4],
            "and keeps growing: {:.4} after 10 ft, {:.4} after 40 ft",
            open[4],
            open[19]
        );
        // With landmarks the map stays a small fraction of dead reckoning's the whole way.
        let worst = held.iter().copied().fold(0.0, f64::max);
        assert!(
            worst < open[19] / 20.0,
            "seed {seed}: largest {worst:.5} m^2 vs {:.5} m^2 unchecked",
            open[19]
        );
        ratios.push(held[19] / open[19]);
        if seed == 0 {
            println!(
                "area after 10, 20, 30, 40 ft without landmarks: {:.4} {:.4} {:.4} {:.4} m^2",
                open[4], open[9], open[14], open[19]
            );
            println!(
                "area after 10, 20, 30, 40 ft with landmarks:    {:.5} {:.5} {:.5} {:.5} m^2",
                held[4], held[9], held[14], held[19]
            );
        }
    }
    ratios.sort_by(f64::total_cmp);
    println!(
        "area at 40 ft with / without landmarks over 20 seeds: median {:.5}, worst {:.5}",
        ratios[10], ratios[19]
    );
}
