//! Angle wrapping: one definition for every heading difference in Harvey.

use std::f64::consts::{PI, TAU};

/// `a` (radians) wrapped into `(-π, π]`.
pub fn wrap(a: f64) -> f64 {
    let t = a.rem_euclid(TAU);
    if t > PI { t - TAU } else { t }
}

/// `a` (degrees) wrapped into `(-180, 180]`.
pub fn wrap_deg(a: f64) -> f64 {
    let t = a.rem_euclid(360.0);
    if t > 180.0 { t - 360.0 } else { t }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wraps_into_the_half_open_turn() {
        assert_eq!(wrap(0.0), 0.0);
        assert_eq!(wrap(PI), PI);
        assert_eq!(wrap(-PI), PI);
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap(-0.5 * PI - TAU) + 0.5 * PI).abs() < 1e-12);
        assert!((wrap(7.0) - (7.0 - TAU)).abs() < 1e-12);
        for k in -50..50 {
            let w = wrap(k as f64 * 0.37);
            assert!(w > -PI && w <= PI, "{w}");
        }
        assert_eq!(wrap_deg(180.0), 180.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(-190.0), 170.0);
        assert_eq!(wrap_deg(725.0), 5.0);
    }
}
