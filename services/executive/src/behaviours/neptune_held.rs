//! A step of CMU's navigation the sonar's panic-stop holds back (001 §6.2): the ring's near
//! echoes, each confirmed by a second reading, mapped as obstacles across their beams, and how
//! far the way behind lets the robot back off.

use harvey_msgs::{SONAR_SENSORS, SonarRing};

use super::Neptune;
use crate::script::clearance::Clearance;

/// The sonar ring as the robot knows it (the world's `[robot]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sonar {
    /// The ring's radius (m): an echo's range is from the ring, not the robot's centre.
    pub ring_m: f64,
    /// A sensor's beam, all of it (rad): an echo comes from something somewhere across it.
    pub beam_rad: f64,
}

/// An echo is mapped as points across its beam at most this far apart (rad; 5 degrees).
const ARC_STEP_RAD: f64 = 0.087;

/// Each sensor's fresh readings in a row that put something within the planner's clearance
/// (one alone may be crosstalk, as the sonar service's panic-stop also asks for two).
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct NearStreaks {
    stamp_ns: [u64; SONAR_SENSORS],
    count: [u8; SONAR_SENSORS],
}

impl NearStreaks {
    /// Counts the sensors `ring` read afresh: on while the echo is within `near_m` of the
    /// robot's centre (`ring_m` out to the sensors), back to 0 when it is not.
    pub(super) fn update(&mut self, ring: &SonarRing, ring_m: f64, near_m: f64) {
        for i in 0..SONAR_SENSORS {
            if ring.reading_stamp_ns[i] == self.stamp_ns[i] {
                continue;
            }
            self.stamp_ns[i] = ring.reading_stamp_ns[i];
            let range = f64::from(ring.range_m[i]);
            let near = ring.valid_mask & (1 << i) != 0 && range.is_finite() && ring_m + range <= near_m;
            self.count[i] = if near { self.count[i].saturating_add(1) } else { 0 };
        }
    }

    fn confirmed(&self, i: usize) -> bool {
        self.count[i] >= 2
    }
}

impl Neptune {
    /// The ring's confirmed echoes within the planner's clearance, mapped where the model puts
    /// them: what held the robot back (the panic-stop watches ahead; whatever else is that near
    /// counts too), each as an arc across its beam from its sensor (the echo says how far, not
    /// where across the beam: the sonar maps of Moravec and Elfes, 003's lab). The route that
    /// led here is dropped.
    pub(super) fn map_echoes(&mut self) {
        let Some(ring) = self.ring else { return };
        let at = self.believed();
        let half = self.sonar.beam_rad / 2.0;
        let n = (half / ARC_STEP_RAD).ceil().max(1.0) as i32;
        let mut echoes = 0;
        for i in (0..SONAR_SENSORS).filter(|&i| self.near.confirmed(i)) {
            let b = at.heading_rad + f64::from(ring.bearing_rad[i]);
            let d = f64::from(ring.range_m[i]);
            let sensor = [at.x_m + self.sonar.ring_m * b.cos(), at.y_m + self.sonar.ring_m * b.sin()];
            echoes += 1;
            for k in -n..=n {
                let a = b + half * f64::from(k) / f64::from(n);
                self.obstacles.push(([sensor[0] + d * a.cos(), sensor[1] + d * a.sin()], sensor));
            }
        }
        self.route.clear();
        self.holds += 1;
        tracing::info!(
            stop = self.stops,
            echoes,
            holds = self.holds,
            "held back by the panic-stop: near echoes mapped"
        );
    }

    /// How far the robot may back now: the way behind as the latest ring shows it (no
    /// panic-stop watches it), at most `back_off_m`.
    pub(super) fn room_behind(&self) -> f64 {
        let clear = self.ring.as_ref().map_or(0.0, |r| Clearance::of(r).may_back_m());
        clear.min(self.g.back_off_m)
    }
}
