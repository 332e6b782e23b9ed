//! Plane distances: a point's distance to a line segment, one definition for the UMS's polygon
//! and the executive's region gate.

/// The distance from `p` to the segment `a`-`b` (to `a` when the segment is a point).
pub fn distance_to_segment(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let e = [b[0] - a[0], b[1] - a[1]];
    let len2 = e[0] * e[0] + e[1] * e[1];
    let t =
        if len2 > 0.0 { (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a[0] + t * e[0] - p[0]).hypot(a[1] + t * e[1] - p[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beside_beyond_and_on_a_point_segment() {
        assert_eq!(distance_to_segment([0.0, 0.0], [4.0, 0.0], [2.0, 3.0]), 3.0, "beside: perpendicular");
        assert_eq!(distance_to_segment([0.0, 0.0], [4.0, 0.0], [7.0, 4.0]), 5.0, "beyond b: to b");
        assert_eq!(distance_to_segment([1.0, 1.0], [1.0, 1.0], [4.0, 5.0]), 5.0, "a point segment");
    }
}
