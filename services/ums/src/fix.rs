//! A pose fix from the executive's plan-level servoing (000 §5.6, `executive/pose`): landmark
//! vertices placed the robot to within an inch or so, so at the fix's stamp the map becomes a
//! small square round the refined position with a narrow heading wedge, and the growth since is
//! replayed (the fix may arrive after later odometry).

use harvey_msgs::PoseFix;

use crate::map::Map;
use crate::{FixError, Ums};

impl Ums {
    /// Applies a pose fix; a fix holding a non-finite number is refused, the map untouched.
    pub fn on_fix(&mut self, f: &PoseFix) -> Result<(), FixError> {
        let (p, stamp_ns) = (f.refined, f.header.stamp_ns);
        if ![p.x_m, p.y_m, p.heading_rad].iter().all(|v| v.is_finite()) {
            return Err(FixError::NotFinite { stamp_ns });
        }
        let (r, h) = (self.config.fix_m, self.config.fix_heading_rad);
        let square =
            [[p.x_m - r, p.y_m - r], [p.x_m + r, p.y_m - r], [p.x_m + r, p.y_m + r], [p.x_m - r, p.y_m + r]];
        self.rewrite_at(
            stamp_ns,
            || FixError::TooOld { stamp_ns },
            |_| Ok(Map::region(&square, p.heading_rad, h, h)),
        )
    }
}
