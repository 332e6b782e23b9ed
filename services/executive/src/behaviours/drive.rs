//! Motor schemas on the real robot (004 §2.1, 001 §3.1): the sonar ring's echoes as obstacles
//! for avoid-static-obstacle and its open bearings for probe, the summed vector turned into the
//! DRV's velocity command (speed along the heading, turn rate towards the vector), and the
//! vectors kept for the published behaviour state.

use harvey_geometry::wrap;
use harvey_msgs::{CommandKind, Header, MotionCommand, Pose2, SonarRing};

use super::schemas::{V2, avoid_obstacle, combine};

/// How the schemas are weighted and the vector driven.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveParams {
    /// Top speed (m/s) and turn rate (rad/s), and the turn rate per radian of heading error.
    pub max_speed_mps: f64,
    pub max_turn_radps: f64,
    pub turn_gain: f64,
    /// avoid-static-obstacle: the robot's radius, the sphere of influence beyond it, the gain
    /// at contact with the sphere (m/s).
    pub robot_radius_m: f64,
    pub sphere_m: f64,
    pub avoid_gain: f64,
}

/// The schemas' vectors this tick (world frame, m/s): move-to-goal, avoid-static-obstacle,
/// noise, avoid-past, probe; and their clipped sum.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Vectors {
    pub parts: [V2; 5],
    pub sum: V2,
}

impl Vectors {
    /// The five parts and the sum as `x0 y0 x1 y1 ...` (the published layout).
    pub fn flat(&self) -> [f64; 12] {
        let mut out = [0.0; 12];
        for (k, v) in self.parts.iter().chain([&self.sum]).enumerate() {
            (out[2 * k], out[2 * k + 1]) = (v.x, v.y);
        }
        out
    }
}

impl DriveParams {
    /// The settings a behaviour's goal table gives (turn rate in degrees per second); the
    /// robot's radius is the sonar ring's.
    pub fn new(
        max_speed_mps: f64,
        max_turn_degps: f64,
        turn_gain: f64,
        robot_radius_m: f64,
        avoid: (f64, f64),
    ) -> Self {
        let (sphere_m, avoid_gain) = avoid;
        Self {
            max_speed_mps,
            max_turn_radps: max_turn_degps.to_radians(),
            turn_gain,
            robot_radius_m,
            sphere_m,
            avoid_gain,
        }
    }
}

/// The ring's valid echoes as (bearing, range): the bearing from `heading` (0: relative to the
/// robot), the range from the robot's centre (`sensor_ring_m` out to the sensors).
pub fn echoes(ring: &SonarRing, heading: f64, sensor_ring_m: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
    (0..ring.range_m.len())
        .filter(|&i| ring.valid_mask & (1 << i) != 0 && ring.range_m[i].is_finite())
        .map(move |i| (heading + f64::from(ring.bearing_rad[i]), sensor_ring_m + f64::from(ring.range_m[i])))
}

/// avoid-static-obstacle over the ring's echoes: each valid echo is a small obstacle where the
/// sensor saw it; their pushes add up.
pub fn avoid_echoes(ring: &SonarRing, at: Pose2, sensor_ring_m: f64, p: &DriveParams) -> V2 {
    let here = V2::new(at.x_m, at.y_m);
    echoes(ring, at.heading_rad, sensor_ring_m)
        .map(|(b, d)| here.plus(V2::new(b.cos(), b.sin()).scale(d)))
        .fold(V2::default(), |v, echo| {
            v.plus(avoid_obstacle(here, echo, p.robot_radius_m, p.sphere_m, p.avoid_gain, 10.0))
        })
}

/// The sum of `parts`, clipped to the top speed.
pub fn vectors(parts: [V2; 5], p: &DriveParams) -> Vectors {
    Vectors { parts, sum: combine(&parts, p.max_speed_mps) }
}

/// The velocity command for vector `v` from the pose `at`: turn towards it, and drive along the
/// heading with its component there (none while it points behind).
pub fn velocity(v: V2, at: Pose2, p: &DriveParams) -> (f64, f64) {
    if v.norm() < 1e-6 {
        return (0.0, 0.0);
    }
    let e = wrap(v.y.atan2(v.x) - at.heading_rad);
    let speed = (v.norm() * e.cos()).max(0.0).min(p.max_speed_mps);
    (speed, (p.turn_gain * e).clamp(-p.max_turn_radps, p.max_turn_radps))
}

/// While the sonar's panic-stop holds (001 §6.2: something is right ahead), the vehicle takes
/// no command forward: the speed drops to nothing and only the turn (or backing) is left.
pub fn held(ring: Option<&SonarRing>, (v, w): (f64, f64)) -> (f64, f64) {
    if ring.is_some_and(|r| r.panic_stop != 0) { (v.min(0.0), w) } else { (v, w) }
}

/// A velocity command with id `id`.
pub fn command(id: u32, stamp_ns: u64, (v, w): (f64, f64)) -> MotionCommand {
    MotionCommand {
        header: Header::new(u64::from(id), stamp_ns),
        kind: CommandKind::Velocity as u32,
        linear_mps: v,
        angular_radps: w,
        command_id: id,
        ..MotionCommand::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: DriveParams = DriveParams {
        max_speed_mps: 0.3,
        max_turn_radps: 0.5,
        turn_gain: 1.5,
        robot_radius_m: 0.25,
        sphere_m: 1.0,
        avoid_gain: 0.3,
    };

    #[test]
    fn the_vector_becomes_speed_along_the_heading_and_a_turn_towards_it() {
        let at = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.0 };
        assert_eq!(velocity(V2::new(0.2, 0.0), at, &P), (0.2, 0.0));
        let (v, w) = velocity(V2::new(0.2, 0.2), at, &P);
        assert!((v - 0.2).abs() < 1e-9 && (w - 0.5).abs() < 1e-9, "{v} {w}");
        // Behind: turn on the spot.
        let (v, w) = velocity(V2::new(-0.2, 0.01), at, &P);
        assert!(v == 0.0 && w == 0.5);
        assert_eq!(velocity(V2::default(), at, &P), (0.0, 0.0));
    }

    #[test]
    fn echoes_ahead_push_back_and_far_ones_do_not() {
        let mut ring = SonarRing { valid_mask: 0b1, ..SonarRing::default() };
        ring.range_m[0] = 0.5;
        let at = Pose2 { x_m: 1.0, y_m: 2.0, heading_rad: std::f64::consts::FRAC_PI_2 };
        let push = avoid_echoes(&ring, at, 0.23, &P);
        assert!(push.y < -0.1 && push.x.abs() < 1e-9, "{push:?}");
        ring.range_m[0] = 3.0;
        assert_eq!(avoid_echoes(&ring, at, 0.23, &P), V2::default());
        let all =
            vectors([V2::new(1.0, 0.0), V2::new(0.0, 1.0), V2::default(), V2::default(), V2::default()], &P);
        assert!((all.sum.norm() - 0.3).abs() < 1e-12 && all.flat()[10] > 0.0);
        ring.panic_stop = 1;
        assert_eq!(held(Some(&ring), (0.2, 0.4)), (0.0, 0.4));
        assert_eq!(held(Some(&ring), (-0.1, 0.0)), (-0.1, 0.0));
        ring.panic_stop = 0;
        assert_eq!(held(Some(&ring), (0.2, 0.4)), (0.2, 0.4));
    }
}
