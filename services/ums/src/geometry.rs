//! Convex-polygon geometry for the uncertainty map: hulls, half-plane slicing, areas,
//! containment, enclosing arcs, and reducing a hull to a vertex budget without ever shrinking it.

use harvey_geometry::distance_to_segment;

pub type Pt = [f64; 2];

fn cross(o: Pt, a: Pt, b: Pt) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Convex hull, counter-clockwise, without collinear points (Andrew's monotone chain).
pub fn hull(points: &[Pt]) -> Vec<Pt> {
    let mut pts: Vec<Pt> = points.iter().copied().filter(|p| p[0].is_finite() && p[1].is_finite()).collect();
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let mut out: Vec<Pt> = Vec::with_capacity(pts.len() + 1);
    for pass in 0..2 {
        let start = out.len();
        let iter: Box<dyn Iterator<Item = &Pt>> =
            if pass == 0 { Box::new(pts.iter()) } else { Box::new(pts.iter().rev()) };
        for &p in iter {
            while out.len() >= start + 2 && cross(out[out.len() - 2], out[out.len() - 1], p) <= 1e-12 {
                out.pop();
            }
            out.push(p);
        }
        out.pop();
    }
    out
}

/// Area of a polygon (counter-clockwise positive).
pub fn area(poly: &[Pt]) -> f64 {
    let n = poly.len();
    if n < 3 {
        return 0.0;
    }
    (0..n).map(|i| poly[i][0] * poly[(i + 1) % n][1] - poly[(i + 1) % n][0] * poly[i][1]).sum::<f64>() / 2.0
}

/// Whether `p` lies in the convex counter-clockwise polygon (boundary included, within `tol`).
pub fn contains(poly: &[Pt], p: Pt, tol: f64) -> bool {
    match poly.len() {
        0 => false,
        1 => (poly[0][0] - p[0]).hypot(poly[0][1] - p[1]) <= tol,
        2 => distance_to_segment(poly[0], poly[1], p) <= tol,
        n => (0..n).all(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            cross(a, b, p) / (b[0] - a[0]).hypot(b[1] - a[1]).max(1e-300) >= -tol
        }),
    }
}

/// The point of the convex polygon nearest to `p`.
pub fn nearest_point(poly: &[Pt], p: Pt) -> Pt {
    if poly.len() >= 3 && contains(poly, p, 0.0) {
        return p;
    }
    let n = poly.len();
    let mut best = poly.first().copied().unwrap_or(p);
    let mut best_d = f64::INFINITY;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let len2 = e[0] * e[0] + e[1] * e[1];
        let t = if len2 > 0.0 {
            (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + t * e[0], a[1] + t * e[1]];
        let d = (q[0] - p[0]).hypot(q[1] - p[1]);
        if d < best_d {
            best_d = d;
            best = q;
        }
    }
    best
}

/// Keeps the part of a convex polygon where `n . x <= c` (Sutherland–Hodgman on one edge).
pub fn clip(poly: &[Pt], n: Pt, c: f64) -> Vec<Pt> {
    let side = |p: Pt| n[0] * p[0] + n[1] * p[1] - c;
    let mut out = Vec::with_capacity(poly.len() + 1);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (sa, sb) = (side(a), side(b));
        if sa <= 0.0 {
            out.push(a);
        }
        if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
            let t = sa / (sa - sb);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    hull(&out)
}

/// Points whose polygon encloses the arc of radius `r` around `c` from angle `a0` to `a1`
/// (counter-clockwise, `a1 >= a0`), with the arc's chord side included.
pub fn arc_enclosure(c: Pt, r: f64, a0: f64, a1: f64) -> Vec<Pt> {
    let span = (a1 - a0).max(0.0);
    let steps = ((span / 10f64.to_radians()).ceil() as usize).max(1);
    let half = span / steps as f64 / 2.0;
    // Vertices at the ends on the arc, and between them on tangents: radius r / cos(half step).
    let mut pts = vec![[c[0] + r * a0.cos(), c[1] + r * a0.sin()]];
    for k in 0..steps {
        let a = a0 + (2 * k + 1) as f64 * half;
        let rr = r / half.cos();
        pts.push([c[0] + rr * a.cos(), c[1] + rr * a.sin()]);
    }
    pts.push([c[0] + r * a1.cos(), c[1] + r * a1.sin()]);
    pts
}

/// Reduces a convex polygon to at most `max` vertices by repeatedly replacing two neighbours
/// with the meeting point of their outer edges' extensions, choosing the smallest added area.
/// The result always contains the input.
pub fn limit_vertices(mut poly: Vec<Pt>, max: usize) -> Vec<Pt> {
    while poly.len() > max.max(3) {
        let n = poly.len();
        let mut best: Option<(f64, usize, Pt)> = None;
        for i in 0..n {
            let (p0, p1, p2, p3) = (poly[(i + n - 1) % n], poly[i], poly[(i + 1) % n], poly[(i + 2) % n]);
            let d1 = [p1[0] - p0[0], p1[1] - p0[1]];
            let d2 = [p2[0] - p3[0], p2[1] - p3[1]];
            let den = d1[0] * d2[1] - d1[1] * d2[0];
            if den.abs() < 1e-15 {
                continue;
            }
            let t = ((p3[0] - p0[0]) * d2[1] - (p3[1] - p0[1]) * d2[0]) / den;
            if t < 1.0 {
                continue; // the extensions meet behind: this pair cannot be merged outward
            }
            let q = [p0[0] + t * d1[0], p0[1] + t * d1[1]];
            let added = cross(p1, q, p2).abs() / 2.0;
            if best.is_none_or(|(a, _, _)| added < a) {
                best = Some((added, i, q));
            }
        }
        let Some((_, i, q)) = best else { break };
        poly[i] = q;
        poly.remove((i + 1) % n);
        poly = hull(&poly);
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_area_and_containment() {
        let h = hull(&[[0.0, 0.0], [2.0, 0.0], [1.0, 1.0], [2.0, 2.0], [0.0, 2.0], [1.0, 0.0]]);
        assert_eq!(h.len(), 4);
        assert!((area(&h) - 4.0).abs() < 1e-12);
        assert!(
            contains(&h, [1.0, 1.0], 0.0)
                && contains(&h, [2.0, 1.0], 1e-9)
                && !contains(&h, [2.1, 1.0], 1e-9)
        );
        assert_eq!(nearest_point(&h, [3.0, 1.0]), [2.0, 1.0]);
    }

    #[test]
    fn clipping_keeps_one_side() {
        let sq = hull(&[[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]);
        let half = clip(&sq, [1.0, 0.0], 1.0);
        assert!((area(&half) - 2.0).abs() < 1e-12);
        assert!(clip(&sq, [1.0, 0.0], -1.0).is_empty());
        assert_eq!(clip(&sq, [1.0, 0.0], 5.0).len(), 4);
    }

    #[test]
    fn arcs_are_enclosed() {
        let pts = arc_enclosure([0.0, 0.0], 2.0, 0.0, 1.5);
        let h = hull(&[pts.as_slice(), &[[0.0, 0.0]]].concat());
        for k in 0..=100 {
            let a = 1.5 * k as f64 / 100.0;
            assert!(contains(&h, [2.0 * a.cos(), 2.0 * a.sin()], 1e-9), "arc point {a}");
        }
    }

    #[test]
    fn limiting_vertices_only_grows() {
        let circle: Vec<Pt> =
            (0..100).map(|k| k as f64 * std::f64::consts::TAU / 100.0).map(|a| [a.cos(), a.sin()]).collect();
        let h = hull(&circle);
        let small = limit_vertices(h.clone(), 12);
        assert!(small.len() <= 12);
        assert!(h.iter().all(|p| contains(&small, *p, 1e-9)));
        assert!(area(&small) < std::f64::consts::PI * 1.05, "{}", area(&small));
    }
}
