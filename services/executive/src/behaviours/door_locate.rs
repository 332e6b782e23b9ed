//! Locating the wall before door finding (001 §3.2: "first locating the wall and moving the
//! robot in a position parallel to it"): the robot stands while every sensor of the ring reads
//! a few times; each sensor's median reading (a lost echo or a stray outvoted) and the wall as
//! the nearest of them on its side, its normal the mean bearing of the sensors round it whose
//! echoes lie within the gate of it (each beam echoes from the wall's nearest point when the
//! perpendicular falls inside it; a corner further round does not join).

use harvey_geometry::wrap;
use harvey_msgs::{Pose2, SONAR_SENSORS, SonarRing};

use super::wall::Line;

/// Readings each sensor gives before the wall is located (one every three of the DRV's banks:
/// 0.75 s standing at 20 Hz banks).
pub const READINGS: usize = 5;

/// The ring's readings taken so far: ranges of the echoes (m from the sensor), per sensor.
#[derive(Debug, Clone, Default)]
pub struct Look {
    echoes: Vec<Vec<f64>>,
    taken: [usize; SONAR_SENSORS],
    stamps: [u64; SONAR_SENSORS],
    bearings: [f64; SONAR_SENSORS],
}

impl Look {
    /// Takes the ring's new readings made after `since_ns`.
    pub fn take(&mut self, r: &SonarRing, since_ns: u64) {
        self.echoes.resize(SONAR_SENSORS, Vec::new());
        for i in 0..SONAR_SENSORS {
            let t = r.reading_stamp_ns[i];
            if t <= since_ns || t == self.stamps[i] || self.taken[i] >= READINGS {
                continue;
            }
            (self.stamps[i], self.taken[i], self.bearings[i]) =
                (t, self.taken[i] + 1, f64::from(r.bearing_rad[i]));
            if r.valid_mask & (1 << i) != 0 && r.range_m[i].is_finite() {
                self.echoes[i].push(f64::from(r.range_m[i]));
            }
        }
    }

    /// Sensor `i`'s median echo (m from the robot's centre), if most of its readings echoed.
    fn median(&self, i: usize, ring_m: f64) -> Option<f64> {
        let mut e = self.echoes.get(i)?.clone();
        if e.len() * 2 <= READINGS {
            return None;
        }
        e.sort_by(f64::total_cmp);
        Some(ring_m + e[e.len() / 2])
    }

    /// The wall on side `side` (+1 left, -1 right) once every sensor has read enough, seen from
    /// `at`; none before, or when no sensor on that side echoes.
    pub fn wall(&self, at: Pose2, side: f64, ring_m: f64, gate_m: f64) -> Option<Line> {
        if self.taken.iter().any(|&k| k < READINGS) {
            return None;
        }
        let n = SONAR_SENSORS;
        // The wall is on its side: within 50 degrees of square to the robot (a corner behind or
        // ahead, as far off as the wall, must not pass for it).
        let on_side = |i: usize| {
            (wrap(self.bearings[i] * side) - std::f64::consts::FRAC_PI_2).abs() < 50f64.to_radians()
        };
        let (nearest, near) = (0..n)
            .filter(|&i| on_side(i))
            .filter_map(|i| Some((i, self.median(i, ring_m)?)))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        let joins = |i: usize| self.median(i, ring_m).is_some_and(|d| d <= near + gate_m);
        let mut offsets = vec![0.0];
        for step in [1, n - 1] {
            let mut i = (nearest + step) % n;
            while offsets.len() < n / 2 && joins(i) {
                offsets.push(wrap(self.bearings[i] - self.bearings[nearest]));
                i = (i + step) % n;
            }
        }
        let bearing = self.bearings[nearest] + offsets.iter().sum::<f64>() / offsets.len() as f64;
        Some(Line::seen_from([at.x_m, at.y_m], wrap(at.heading_rad + bearing), near))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring 0.77 m from a wall square to sensor 6 (left), 1.0 m from one behind: sensors
    /// 5..7 echo the wall's nearest point, 4 and 8 a little further.
    fn ring(stamp: u64, lost: Option<usize>) -> SonarRing {
        let mut r = SonarRing::default();
        for i in 0..SONAR_SENSORS {
            r.bearing_rad[i] = (i as f64 * std::f64::consts::TAU / 24.0) as f32;
            r.reading_stamp_ns[i] = stamp;
            let range = match i {
                5..=7 => 0.77,
                4 | 8 => 0.80,
                12 => 0.77,
                _ => 3.0,
            };
            r.range_m[i] = range;
            if lost != Some(i) {
                r.valid_mask |= 1 << i;
            }
        }
        r
    }

    #[test]
    fn the_wall_is_located_square_to_its_nearest_echoes_through_lost_echoes() {
        let mut look = Look::default();
        let at = Pose2 { x_m: 1.0, y_m: 0.0, heading_rad: 0.0 };
        assert!(look.wall(at, 1.0, 0.23, 0.08).is_none(), "nothing read yet");
        // Sensor 5's echo lost twice in five, sensor 6's once: the medians hold.
        for k in 1..=5u64 {
            let lost = match k {
                1 | 3 => Some(5),
                2 => Some(6),
                _ => None,
            };
            look.take(&ring(k, lost), 0);
        }
        let line = look.wall(at, 1.0, 0.23, 0.08).expect("located");
        assert!((line.normal_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-6, "{}", line.normal_rad);
        assert!((line.distance([1.0, 0.0]) - 1.0).abs() < 1e-6);
        // The wall behind (sensor 12, as near) is not on the left, nor on the right, where the
        // nearest is 3 m off.
        let right = look.wall(at, -1.0, 0.23, 0.08).expect("located");
        assert!((right.distance([1.0, 0.0]) - 3.23).abs() < 1e-6);
    }
}
