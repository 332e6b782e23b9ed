//! What the latest sonar ring says of the way out after a reflex: whether the panic-stop sees
//! something too close ahead (a forward MOVE then waits rather than creep into it, as the
//! panic-stop only stops a vehicle already driving forward), and how far the way behind is clear
//! (no panic-stop watches it: a recovery backs up only that far).

use harvey_msgs::SonarRing;

/// Room kept behind a backing robot (m): no panic-stop watches behind, so it backs up only
/// where the ring shows this much more than the distance clear (half the forward panic-stop's
/// 2 ft, 001 §6.2, at the same slow speed).
pub const BACKING_MARGIN_M: f64 = 0.3;

/// The readings within this angle of ahead are the panic-stop's; the same angle of straight
/// behind watches the way back (the bearings are f32: a millionth of a radian of slack).
const ARC_RAD: f64 = harvey_msgs::PANIC_STOP_ARC_RAD + 1e-6;

/// The panic-stop watches 30 degrees either way of ahead; what it sees nearest within 15 degrees
/// is in the robot's way (at its 2 ft a reading 15 degrees off is 0.16 m to the side, inside the
/// robot's 0.23 m radius; 30 degrees off, 0.3 m: a doorway's jamb beside the way through).
const PATH_ARC_RAD: f64 = harvey_msgs::PANIC_STOP_ARC_RAD / 2.0 + 1e-6;

/// The latest ring's reading of the way ahead and behind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// The ring's panic-stop flag (a reading ahead under the panic-stop's distance), with the
    /// nearest reading ahead in the robot's way, not beside it.
    pub blocked_ahead: bool,
    /// The nearest valid reading within 30 degrees of straight behind (m; infinite if none).
    pub behind_m: f64,
}

impl Default for Clearance {
    /// Before any ring: nothing known ahead, nothing behind to back into.
    fn default() -> Self {
        Self { blocked_ahead: false, behind_m: 0.0 }
    }
}

impl Clearance {
    pub fn of(ring: &SonarRing) -> Self {
        // The nearest valid reading within `arc` of `towards`: its range and bearing off it.
        let nearest = |towards: f64, arc: f64| {
            (0..ring.range_m.len())
                .filter(|&i| ring.valid_mask & (1 << i) != 0)
                .map(|i| {
                    (
                        f64::from(ring.range_m[i]),
                        harvey_geometry::wrap(f64::from(ring.bearing_rad[i]) - towards),
                    )
                })
                .filter(|&(_, off)| off.abs() <= arc)
                .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a })
        };
        let (_, ahead_off) = nearest(0.0, ARC_RAD);
        let (behind_m, _) = nearest(std::f64::consts::PI, ARC_RAD);
        Self { blocked_ahead: ring.panic_stop != 0 && ahead_off.abs() <= PATH_ARC_RAD, behind_m }
    }

    /// How far the robot may back up.
    pub fn may_back_m(&self) -> f64 {
        (self.behind_m - BACKING_MARGIN_M).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::SONAR_SENSORS;

    fn ring(ranges: impl Fn(usize) -> f32, panic_stop: bool) -> SonarRing {
        let mut r = SonarRing {
            valid_mask: (1 << SONAR_SENSORS) - 1,
            panic_stop: u32::from(panic_stop),
            ..Default::default()
        };
        for i in 0..SONAR_SENSORS {
            r.bearing_rad[i] = (i as f64 * std::f64::consts::TAU / SONAR_SENSORS as f64) as f32;
            r.range_m[i] = ranges(i);
        }
        r
    }

    #[test]
    fn the_way_ahead_is_blocked_by_what_is_in_the_robots_way_not_by_a_jamb_beside_it() {
        // The panic-stop's flag with the nearest reading dead ahead, 15 degrees off, 30 off.
        let near = |k: usize| Clearance::of(&ring(move |i| if i == k { 0.5 } else { 3.0 }, true));
        assert!(near(0).blocked_ahead && near(1).blocked_ahead && near(23).blocked_ahead);
        assert!(!near(2).blocked_ahead && !near(22).blocked_ahead, "a jamb 30 degrees off");
        assert!(!Clearance::of(&ring(|_| 0.5, false)).blocked_ahead, "no flag, no block");
    }

    #[test]
    fn the_way_behind_is_the_nearest_reading_within_30_degrees_of_straight_behind() {
        // Sensor 12 is straight behind, 10 and 14 30 degrees off it, 9 and 15 45.
        let c = Clearance::of(&ring(
            |i| {
                if i == 14 {
                    1.1
                } else if i == 9 {
                    0.4
                } else {
                    3.0
                }
            },
            true,
        ));
        assert!(c.blocked_ahead);
        assert!((c.behind_m - 1.1).abs() < 1e-6 && (c.may_back_m() - 0.8).abs() < 1e-6, "{c:?}");
        let mut r = ring(|_| 3.0, false);
        r.valid_mask = 0;
        assert_eq!(Clearance::of(&r).behind_m, f64::INFINITY, "no echo: nothing behind");
        assert_eq!(Clearance::default().may_back_m(), 0.0, "no ring yet: no backing");
    }
}
