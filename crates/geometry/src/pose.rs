//! The planar pose: position in metres and heading in radians, with composition, inverse and
//! relative pose, and the arc a wheeled robot drives. The same type travels in messages.

use iceoryx2_bb_derive_macros::ZeroCopySend;
use iceoryx2_bb_elementary_traits::zero_copy_send::ZeroCopySend;

/// A planar pose: position in metres and heading in radians (counter-clockwise from +x). As a
/// transform `a_from_b`, it maps coordinates in frame `b` into frame `a`.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend, serde::Serialize, serde::Deserialize)]
#[repr(C)]
#[type_name("harvey_msgs/Pose2")]
pub struct Pose2 {
    pub x_m: f64,
    pub y_m: f64,
    pub heading_rad: f64,
}

impl Pose2 {
    pub const fn new(x_m: f64, y_m: f64, heading_rad: f64) -> Self {
        Self { x_m, y_m, heading_rad }
    }

    /// A pose whose heading is given in degrees (as world and launch files give them).
    pub fn from_degrees(x_m: f64, y_m: f64, heading_deg: f64) -> Self {
        Self { x_m, y_m, heading_rad: heading_deg.to_radians() }
    }

    /// `self ∘ other`: with `self = a_from_b` and `other = b_from_c`, the pose `a_from_c`. The
    /// heading is summed, not wrapped.
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        let [x_m, y_m] = self.apply([other.x_m, other.y_m]);
        Pose2 { x_m, y_m, heading_rad: self.heading_rad + other.heading_rad }
    }

    /// The inverse transform: `b_from_a` for `self = a_from_b`.
    pub fn inverse(&self) -> Pose2 {
        let (s, c) = self.heading_rad.sin_cos();
        Pose2 {
            x_m: -(c * self.x_m + s * self.y_m),
            y_m: s * self.x_m - c * self.y_m,
            heading_rad: -self.heading_rad,
        }
    }

    /// `other` seen from `self` (both in one frame): `self⁻¹ ∘ other`.
    pub fn relative(&self, other: &Pose2) -> Pose2 {
        self.inverse().compose(other)
    }

    /// A point given in this pose's frame, in the frame the pose is given in.
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.heading_rad.sin_cos();
        [self.x_m + c * p[0] - s * p[1], self.y_m + s * p[0] + c * p[1]]
    }

    /// Distance between the positions of two poses.
    pub fn distance(&self, other: &Pose2) -> f64 {
        (other.x_m - self.x_m).hypot(other.y_m - self.y_m)
    }

    /// The pose reached by driving `s` metres from here while the heading changes linearly by
    /// `dth` over the way (an arc; a straight line when `dth` is 0).
    pub fn arc(&self, s: f64, dth: f64) -> Pose2 {
        let th = self.heading_rad;
        if dth.abs() < 1e-9 {
            return Pose2 { x_m: self.x_m + s * th.cos(), y_m: self.y_m + s * th.sin(), heading_rad: th };
        }
        let r = s / dth;
        Pose2 {
            x_m: self.x_m + r * ((th + dth).sin() - th.sin()),
            y_m: self.y_m - r * ((th + dth).cos() - th.cos()),
            heading_rad: th + dth,
        }
    }

    /// Shifted sideways by `d` metres (positive: to the left of the heading).
    pub fn sideways(&self, d: f64) -> Pose2 {
        let th = self.heading_rad;
        Pose2 { x_m: self.x_m - d * th.sin(), y_m: self.y_m + d * th.cos(), heading_rad: th }
    }
}

/// A pose that does not parse from `x_m,y_m,heading_deg`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("pose `{text}`: {what}")]
pub struct PoseParseError {
    pub text: String,
    pub what: String,
}

impl std::str::FromStr for Pose2 {
    type Err = PoseParseError;

    /// `x_m,y_m,heading_deg`, as a command line gives a start pose (`--start 5,4,-90`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = |what: String| PoseParseError { text: s.to_owned(), what };
        let v: Vec<f64> = s
            .split(',')
            .map(|p| p.trim().parse::<f64>().map_err(|e| err(format!("`{p}`: {e}"))))
            .collect::<Result<_, _>>()?;
        match v[..] {
            [x, y, deg] if v.iter().all(|c| c.is_finite()) => Ok(Pose2::from_degrees(x, y, deg)),
            _ => Err(err("want three finite numbers `x_m,y_m,heading_deg`".to_owned())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Pose2, b: Pose2) -> bool {
        (a.x_m - b.x_m).abs() < 1e-12
            && (a.y_m - b.y_m).abs() < 1e-12
            && (a.heading_rad - b.heading_rad).abs() < 1e-12
    }

    #[test]
    fn composition_inverse_and_relative_agree() {
        let a = Pose2::new(1.0, 2.0, 0.5);
        let b = Pose2::new(-0.3, 0.7, -1.2);
        assert!(close(a.compose(&a.inverse()), Pose2::default()));
        assert!(close(a.inverse().compose(&a), Pose2::default()));
        assert!(close(a.relative(&a.compose(&b)), b));
        let q = Pose2::new(0.0, 0.0, std::f64::consts::FRAC_PI_2).apply([1.0, 0.0]);
        assert!(q[0].abs() < 1e-12 && (q[1] - 1.0).abs() < 1e-12);
        assert!((a.distance(&b) - 1.3_f64.hypot(1.3)).abs() < 1e-12);
    }

    #[test]
    fn an_arc_ends_where_a_straight_drive_or_a_circle_puts_it() {
        let p = Pose2::new(1.0, 2.0, 0.5);
        let straight = p.arc(2.0, 0.0);
        assert!(close(straight, Pose2::new(1.0 + 2.0 * 0.5f64.cos(), 2.0 + 2.0 * 0.5f64.sin(), 0.5)));
        // A quarter circle of radius 1 from the origin heading +x ends at (1, 1) heading +y.
        let q = Pose2::default().arc(std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2);
        assert!(close(q, Pose2::new(1.0, 1.0, std::f64::consts::FRAC_PI_2)));
        assert!(close(Pose2::default().sideways(0.5), Pose2::new(0.0, 0.5, 0.0)));
        // A barely bent arc ends where the straight drive does.
        assert!((p.arc(1e-3, 1e-12).x_m - p.arc(1e-3, 0.0).x_m).abs() < 1e-9);
    }

    #[test]
    fn parses_degrees_from_the_command_line() {
        let p: Pose2 = "5, 4.5,-90".parse().expect("parses");
        assert_eq!(p, Pose2::from_degrees(5.0, 4.5, -90.0));
        let e = "5,4".parse::<Pose2>().expect_err("two numbers");
        assert!(e.to_string().contains("three finite numbers"), "{e}");
        assert!("5,x,0".parse::<Pose2>().expect_err("not a number").to_string().contains("`x`"));
        assert!("5,4,inf".parse::<Pose2>().is_err());
    }
}
