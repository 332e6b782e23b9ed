//! What the executive believes of the robot's pose between fixes: odometry, moved by the last pose
//! fix (plan-level servoing's refinement, or docking's pose from the dock's frame). A fix is kept
//! as `(odometry then, pose then)`, and odometry's later motion is composed onto the fixed pose.

use harvey_msgs::Pose2;

/// Odometry now, the last fix, and how far odometry says the robot went since.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Belief {
    odometry: Pose2,
    fix: Option<(Pose2, Pose2)>,
    travelled_m: f64,
    /// The turn odometry measured since the last fix, either way (rad).
    turned_rad: f64,
}

impl Belief {
    /// Odometry's latest pose.
    pub fn set_odometry(&mut self, odometry: Pose2) {
        self.travelled_m += (odometry.x_m - self.odometry.x_m).hypot(odometry.y_m - self.odometry.y_m);
        self.turned_rad += harvey_geometry::wrap(odometry.heading_rad - self.odometry.heading_rad).abs();
        self.odometry = odometry;
    }

    /// The robot is at `pose` now (odometry's latest pose is the one it goes with).
    pub fn fix(&mut self, pose: Pose2) {
        self.fix = Some((self.odometry, pose));
        (self.travelled_m, self.turned_rad) = (0.0, 0.0);
    }

    /// The turn odometry measured since the last fix, either way (rad).
    pub fn turned_rad(&self) -> f64 {
        self.turned_rad
    }

    /// The path odometry measured since the last fix (since the start without one), m.
    pub fn travelled_m(&self) -> f64 {
        self.travelled_m
    }

    /// Whether any fix has been taken.
    pub fn has_fix(&self) -> bool {
        self.fix.is_some()
    }

    /// The pose believed now.
    pub fn believed(&self) -> Pose2 {
        fixed(self.fix, self.odometry)
    }
}

/// The pose now, from a fix `(odometry then, pose then)` and odometry now: the fixed pose moved
/// by what odometry says happened since (odometry itself without a fix).
pub fn fixed(fix: Option<(Pose2, Pose2)>, odometry: Pose2) -> Pose2 {
    fix.map_or(odometry, |(then, pose)| pose.compose(&relative(then, odometry)))
}

/// `to` in `from`'s frame. (Not `Pose2::relative`, which composes the inverse and so rounds
/// differently: this is the arithmetic the recorded runs were made with.)
pub fn relative(from: Pose2, to: Pose2) -> Pose2 {
    let (c, s) = (from.heading_rad.cos(), from.heading_rad.sin());
    let (dx, dy) = (to.x_m - from.x_m, to.y_m - from.y_m);
    Pose2 { x_m: dx * c + dy * s, y_m: -dx * s + dy * c, heading_rad: to.heading_rad - from.heading_rad }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The composition the executive used before `Pose2::compose`, kept to check that they agree
    /// to the bit.
    fn compose_by_hand(base: Pose2, rel: Pose2) -> Pose2 {
        let (c, s) = (base.heading_rad.cos(), base.heading_rad.sin());
        Pose2 {
            x_m: base.x_m + rel.x_m * c - rel.y_m * s,
            y_m: base.y_m + rel.x_m * s + rel.y_m * c,
            heading_rad: base.heading_rad + rel.heading_rad,
        }
    }

    #[test]
    fn a_fix_carries_odometry_s_later_motion() {
        let mut b = Belief::default();
        b.set_odometry(Pose2::new(1.0, 0.0, 0.0));
        assert_eq!(b.believed(), Pose2::new(1.0, 0.0, 0.0), "no fix: odometry");
        // Fixed 0.2 m to the left of where odometry said, turned a right angle.
        b.fix(Pose2::new(1.0, 0.2, std::f64::consts::FRAC_PI_2));
        assert!(b.has_fix());
        // Odometry then drives 0.5 m ahead: in the fixed frame that is 0.5 m along +y.
        b.set_odometry(Pose2::new(1.5, 0.0, 0.0));
        let p = b.believed();
        assert!((p.x_m - 1.0).abs() < 1e-12 && (p.y_m - 0.7).abs() < 1e-12, "{p:?}");
        assert!((p.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn pose2_compose_rounds_as_the_executive_s_own_did() {
        let mut z = 0x1234_5678_9abc_def0_u64;
        let mut next = || {
            z = z.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            ((z >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 40.0
        };
        for _ in 0..10_000 {
            let (base, rel) = (Pose2::new(next(), next(), next()), Pose2::new(next(), next(), next()));
            let (a, b) = (base.compose(&rel), compose_by_hand(base, rel));
            assert_eq!(
                (a.x_m.to_bits(), a.y_m.to_bits(), a.heading_rad.to_bits()),
                (b.x_m.to_bits(), b.y_m.to_bits(), b.heading_rad.to_bits())
            );
        }
    }
}
