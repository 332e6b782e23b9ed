//! A step of CMU's navigation the sonar's panic-stop holds back (001 §6.2): the ring's near
//! echoes mapped as obstacles across their beams, and whether there is room to back off.

use harvey_geometry::wrap;

use super::Neptune;
use crate::behaviours::drive;

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

impl Neptune {
    /// The ring's echoes within the planner's clearance, mapped where the model puts them: what
    /// held the robot back (the panic-stop watches ahead; whatever else is that near counts too),
    /// each as an arc across its beam (the echo says how far, not where across the beam: the
    /// sonar maps of Moravec and Elfes, 003's lab). The route that led here is dropped.
    pub(super) fn map_echoes(&mut self) {
        let Some(ring) = self.ring else { return };
        let at = self.believed();
        let from = [at.x_m, at.y_m];
        let half = self.sonar.beam_rad / 2.0;
        let n = (half / ARC_STEP_RAD).ceil() as i32;
        let mut echoes = 0;
        for (b, d) in drive::echoes(&ring, at.heading_rad, self.sonar.ring_m) {
            if d > self.g.clearance_m {
                continue;
            }
            echoes += 1;
            for k in -n..=n {
                let a = b + half * f64::from(k) / f64::from(n.max(1));
                self.obstacles.push(([from[0] + d * a.cos(), from[1] + d * a.sin()], from));
            }
        }
        self.route.clear();
        tracing::info!(stop = self.stops, echoes, "held back by the panic-stop: the near echoes mapped");
    }

    /// Whether the ring hears nothing within 30 degrees of straight behind nearer than the
    /// back-off and the planner's clearance.
    pub(super) fn room_behind(&self) -> bool {
        let Some(ring) = &self.ring else { return false };
        let reach = self.g.clearance_m + self.g.back_off_m;
        let behind = std::f64::consts::FRAC_PI_6;
        drive::echoes(ring, 0.0, self.sonar.ring_m)
            .all(|(b, d)| wrap(b - std::f64::consts::PI).abs() > behind || d > reach)
    }
}
