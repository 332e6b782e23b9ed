//! The simulated sonar ring (001 §3): 24 Polaroid sensors fired in 3 banks of 8, ranges in tenths
//! of a foot up to the 25.5 ft limit, a beam of finite width, no echo from walls met at
//! grazing incidence (specular reflection), and round pillars echoing as cylinders.

use harvey_drv_protocol::SONAR_NO_ECHO;
use harvey_geometry::{Rng, wrap};
use harvey_world::{Robot, World};

use crate::motion::{FT, Pose2};

/// Rays cast across one beam.
const RAYS_PER_BEAM: usize = 9;

/// Bearing of sensor `i` in the robot frame: evenly around the ring, sensor 0 straight ahead.
pub fn bearing_rad(i: usize) -> f64 {
    i as f64 * std::f64::consts::TAU / 24.0
}

/// Range of one sensor in tenths of a foot from the sensor face, or [`SONAR_NO_ECHO`].
pub fn read_sensor(world: &World, truth: Pose2, i: usize) -> u16 {
    let r = &world.robot;
    let axis = truth.heading_rad + bearing_rad(i);
    let origin =
        [truth.x_m + r.sonar_ring_radius_m * axis.cos(), truth.y_m + r.sonar_ring_radius_m * axis.sin()];
    let half = (r.sonar_beam_width_deg / 2.0).to_radians();
    let limit = r.sonar_specular_limit_deg.to_radians();
    let max_m = r.sonar_max_range_ft * FT;
    let sampled = (0..RAYS_PER_BEAM)
        .filter_map(|k| {
            let a = axis - half + 2.0 * half * k as f64 / (RAYS_PER_BEAM - 1) as f64;
            world.cast_ray(origin, [a.cos(), a.sin()], max_m)
        })
        .filter(|h| h.incidence_rad <= limit)
        .map(|h| h.distance_m);
    // A wall met head-on somewhere in the beam echoes from its nearest point: the foot of the
    // perpendicular, when that lies inside the beam and nothing stands in front of it.
    let perpendicular = world.walls.iter().enumerate().filter_map(|(i, w)| {
        let e = [w.to[0] - w.from[0], w.to[1] - w.from[1]];
        let len2 = e[0] * e[0] + e[1] * e[1];
        let t = ((origin[0] - w.from[0]) * e[0] + (origin[1] - w.from[1]) * e[1]) / len2;
        if !(0.0..=1.0).contains(&t) {
            return None;
        }
        let foot = [w.from[0] + t * e[0] - origin[0], w.from[1] + t * e[1] - origin[1]];
        let d = foot[0].hypot(foot[1]);
        let off_axis = (foot[1].atan2(foot[0]) - axis + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        if d < 1e-9 || off_axis.abs() > half {
            return None;
        }
        let hit = world.cast_ray(origin, [foot[0] / d, foot[1] / d], max_m)?;
        (hit.wall == i).then_some(hit.distance_m)
    });
    // A round pillar echoes from its point nearest the sensor wherever the beam covers it, if
    // nothing nearer stands in the way (its own faces lie within a centimetre of that point).
    let pillars = world.pillars().iter().filter_map(|p| {
        let c = [p.at[0] - origin[0], p.at[1] - origin[1]];
        let d = c[0].hypot(c[1]);
        let echo = d - p.radius_m;
        if echo <= 0.0 || echo > max_m || wrap(c[1].atan2(c[0]) - axis).abs() > half {
            return None;
        }
        let blocked =
            world.cast_ray(origin, [c[0] / d, c[1] / d], max_m).is_some_and(|h| h.distance_m < echo - 0.02);
        (!blocked).then_some(echo)
    });
    let nearest = sampled.chain(perpendicular).chain(pillars).fold(f64::INFINITY, f64::min);
    if nearest.is_finite() {
        ((nearest / FT) * 10.0).round().min(f64::from(SONAR_NO_ECHO - 1)) as u16
    } else {
        SONAR_NO_ECHO
    }
}

/// Fires bank `bank` (0..3): sensors `bank`, `bank + 3`, ... `bank + 21`, with the ring's
/// imperfections of the world's `[robot]` drawn from `rng` ([`imperfect`]).
pub fn fire_bank(world: &World, truth: Pose2, bank: u8, rng: &mut Rng) -> [u16; 8] {
    let clean = std::array::from_fn(|k| read_sensor(world, truth, bank as usize + 3 * k));
    imperfect(&world.robot, clean, rng)
}

/// A bank's clean ranges as real transducers report them (001 §3): each sensor may hear the
/// echo of another of its bank, fired at the same moment, and keep it when it comes first
/// (crosstalk); an echo may come back by a second wall, 20-100 % long (multipath), or be lost
/// (dropout); and every range has noise. The draws are the same whatever the ranges are, so
/// one reading does not shift the randomness of the next.
pub fn imperfect(r: &Robot, clean: [u16; 8], rng: &mut Rng) -> [u16; 8] {
    let mut out = clean;
    for k in 0..8 {
        let (cross, other) = (rng.uniform(), (k + 1 + (rng.uniform() * 7.0) as usize) % 8);
        let (multi, stretch) = (rng.uniform(), 1.2 + 0.8 * rng.uniform());
        let (drop, noise) = (rng.uniform(), rng.normal(0.0, r.sonar_range_sd_ft));
        if drop < r.sonar_dropout {
            out[k] = SONAR_NO_ECHO;
            continue;
        }
        let mut ft = (clean[k] != SONAR_NO_ECHO).then(|| f64::from(clean[k]) / 10.0);
        if cross < r.sonar_crosstalk && clean[other] != SONAR_NO_ECHO {
            let heard = f64::from(clean[other]) / 10.0;
            ft = Some(ft.map_or(heard, |f| f.min(heard)));
        }
        if multi < r.sonar_multipath {
            ft = ft.map(|f| f * stretch);
        }
        out[k] = match ft.map(|f| f + noise) {
            Some(f) if f < r.sonar_max_range_ft => {
                (f * 10.0).round().clamp(0.0, f64::from(SONAR_NO_ECHO - 1)) as u16
            }
            _ => SONAR_NO_ECHO,
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hallway() -> World {
        harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads")
    }

    #[test]
    fn a_wall_abeam_reads_its_distance_to_a_tenth_of_a_foot() {
        let w = hallway();
        // Robot on the centre line facing +x: sensor 6 (90 degrees) faces the left wall 1 m away.
        let truth = Pose2 { x_m: 2.0, y_m: 0.0, heading_rad: 0.0 };
        let expected = ((1.0 - w.robot.sonar_ring_radius_m) / FT * 10.0).round() as u16;
        assert_eq!(read_sensor(&w, truth, 6), expected, "exact to the tenth of a foot");
        // Any angle inside the beam: the nearest echo is still the perpendicular one.
        for th in [-0.25f64, -0.1, 0.07, 0.25] {
            let turned = Pose2 { heading_rad: th, ..truth };
            let d =
                (1.0 - w.robot.sonar_ring_radius_m * (std::f64::consts::FRAC_PI_2 + th).sin()) / FT * 10.0;
            assert_eq!(read_sensor(&w, turned, 6), d.round() as u16, "robot turned {th} rad");
        }
    }

    #[test]
    fn imperfections_come_at_their_rates_and_a_perfect_ring_reads_clean() {
        let mut r = hallway().robot;
        (r.sonar_range_sd_ft, r.sonar_dropout, r.sonar_crosstalk, r.sonar_multipath) = (0.0, 0.0, 0.0, 0.0);
        let clean = [30, 40, 50, 60, 70, 80, 90, SONAR_NO_ECHO];
        let mut rng = Rng::new(5);
        assert_eq!(imperfect(&r, clean, &mut rng), clean, "no imperfection asked: exact");
        r.sonar_dropout = 0.1;
        let n = 4000;
        let lost: usize = (0..n)
            .map(|_| imperfect(&r, clean, &mut rng)[..7].iter().filter(|&&v| v == SONAR_NO_ECHO).count())
            .sum();
        let rate = lost as f64 / (7 * n) as f64;
        assert!((rate - 0.1).abs() < 0.01, "dropout rate {rate}");
        r.sonar_dropout = 0.0;
        r.sonar_crosstalk = 1.0;
        // Every sensor hears some other of its bank first when that one is nearer: never longer.
        let heard = imperfect(&r, clean, &mut rng);
        assert!(heard.iter().zip(clean).all(|(&h, c)| h <= c), "{heard:?}");
        assert_ne!(heard[7], SONAR_NO_ECHO, "a silent sensor hears its neighbour's echo");
        r.sonar_crosstalk = 0.0;
        r.sonar_range_sd_ft = 0.2;
        let errs: Vec<f64> =
            (0..n).map(|_| f64::from(imperfect(&r, clean, &mut rng)[3]) / 10.0 - 6.0).collect();
        let sd = (errs.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
        assert!((sd - 0.2).abs() < 0.02, "range noise {sd} ft");
    }

    #[test]
    fn a_grazing_wall_returns_no_echo() {
        let w = hallway();
        // Facing along the corridor from its far end region, sensor 0 looks 17 m down the hall
        // at the end wall head-on, but sensor 1 (15 degrees) with the robot hugging the wall sees
        // the side wall only at grazing incidence.
        let truth = Pose2 { x_m: 0.0, y_m: 0.75, heading_rad: 0.0 };
        assert_eq!(read_sensor(&w, truth, 1), SONAR_NO_ECHO);
    }

    #[test]
    fn a_pole_anywhere_in_the_beam_echoes_from_its_nearest_point() {
        let mut w =
            harvey_world::load_str(include_str!("../../../worlds/arena.toml"), "arena").expect("loads");
        let pole = w.place_poles(1).expect("room")[8].at;
        let radius = w.pillars()[8].radius_m;
        // 1.33 m from the pole's centre, on a half circle round it, the robot facing it to
        // within 10 degrees either way. Drawn as eight faces 6 cm wide, the pole is met by one or
        // two of the beam's rays, often at a corner where a face is seen 45 degrees off its
        // normal (no echo); a real pole is round and always echoes from the point facing the
        // sensor (to the reading's tenth of a foot and the faces' 6 mm).
        for side in 0..36 {
            let from = f64::from(side) * 5f64.to_radians();
            let at = Pose2 {
                x_m: pole[0] + 1.33 * from.cos(),
                y_m: pole[1] + 1.33 * from.sin(),
                heading_rad: 0.0,
            };
            for k in -20..=20 {
                let heading_rad = from - std::f64::consts::PI + (f64::from(k) / 2.0).to_radians();
                let sensor = [
                    at.x_m + w.robot.sonar_ring_radius_m * heading_rad.cos(),
                    at.y_m + w.robot.sonar_ring_radius_m * heading_rad.sin(),
                ];
                let expected = (pole[0] - sensor[0]).hypot(pole[1] - sensor[1]) - radius;
                let ft = f64::from(read_sensor(&w, Pose2 { heading_rad, ..at }, 0)) / 10.0;
                let off = f64::from(k) / 2.0;
                assert!(
                    (ft * FT - expected).abs() < 0.025,
                    "from {from:.2} rad, facing {off} degrees off: {ft} ft, {expected:.3} m expected"
                );
            }
        }
    }
}
