//! The camera's view of a path on flat ground, for path following (001 §2.1): the map's edges
//! predicted as image columns at given rows from a pose, and a line-finder fit (the centreline's
//! vanishing point and its middle at the bottom row, each edge) taken back to the ground in the
//! robot's frame (x ahead, y left).

use harvey_geometry::wrap;
use harvey_msgs::Pose2;

/// A level pinhole camera at the robot's centre, `height_m` above the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    pub focal_px: f64,
    pub cx: f64,
    pub cy: f64,
    pub height_m: f64,
}

/// One of the path's segments from the map: its centreline from `from` to `to` (world frame), its
/// left and right edges (each two points, in the direction of travel), and its width (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub left: [[f64; 2]; 2],
    pub right: [[f64; 2]; 2],
    pub width_m: f64,
}

impl Segment {
    /// The segment between two edges (each from its first end to its second): the centreline
    /// joins the middles of their ends.
    pub fn between(left: [[f64; 2]; 2], right: [[f64; 2]; 2]) -> Self {
        let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        let (from, to) = (mid(left[0], right[0]), mid(left[1], right[1]));
        let d = [left[1][0] - left[0][0], left[1][1] - left[0][1]];
        let n = d[0].hypot(d[1]).max(1e-9);
        // The right edge's first end's distance from the left edge's line.
        let width_m = ((right[0][0] - left[0][0]) * d[1] - (right[0][1] - left[0][1]) * d[0]).abs() / n;
        Self { from, to, left, right, width_m }
    }

    pub fn heading(&self) -> f64 {
        (self.to[1] - self.from[1]).atan2(self.to[0] - self.from[0])
    }

    pub fn length_m(&self) -> f64 {
        (self.to[0] - self.from[0]).hypot(self.to[1] - self.from[1])
    }

    /// How far along the centreline `p` lies from its start, and its signed offset (left of the
    /// direction of travel positive).
    pub fn local(&self, p: [f64; 2]) -> (f64, f64) {
        let (s, c) = self.heading().sin_cos();
        let (dx, dy) = (p[0] - self.from[0], p[1] - self.from[1]);
        (c * dx + s * dy, -s * dx + c * dy)
    }
}

/// A fit taken to the ground: the path's direction relative to the robot's heading (rad,
/// counter-clockwise positive), the robot's offset from the centreline (m, left of the direction of
/// travel positive) and the width between the edges (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seen {
    pub heading_rad: f64,
    pub offset_m: f64,
    pub width_m: f64,
}

impl View {
    /// The column where the ground line through `a` and `b` (robot frame) crosses image row `v`,
    /// if that row sees the ground and the line crosses it ahead.
    fn column(&self, a: [f64; 2], b: [f64; 2], v: f64) -> Option<f64> {
        let z = self.depth(v)?;
        let dx = b[0] - a[0];
        if dx.abs() < 1e-9 {
            return None;
        }
        let y = a[1] + (z - a[0]) / dx * (b[1] - a[1]);
        Some(self.cx - self.focal_px * y / z)
    }

    /// The ground's depth ahead at row `v` (none at or above the horizon).
    fn depth(&self, v: f64) -> Option<f64> {
        (v > self.cy + 0.5).then(|| self.focal_px * self.height_m / (v - self.cy))
    }

    /// The segment's left and right edges as columns at rows `top` and `bottom`, seen from `at`
    /// (world frame): `[left_top, left_bottom, right_top, right_bottom]`.
    pub fn predict(&self, s: &Segment, at: Pose2, top: f64, bottom: f64) -> Option<[f64; 4]> {
        let inv = at.inverse();
        let local = |e: [[f64; 2]; 2]| (inv.apply(e[0]), inv.apply(e[1]));
        let (l, r) = (local(s.left), local(s.right));
        Some([
            self.column(l.0, l.1, top)?,
            self.column(l.0, l.1, bottom)?,
            self.column(r.0, r.1, top)?,
            self.column(r.0, r.1, bottom)?,
        ])
    }

    /// A fit's items taken to the ground: `centre` `[vanishing_u, vanishing_v, bottom_u, bottom_v,
    /// ..]`, each edge `[u, v, angle, ..]`.
    pub fn seen(&self, centre: [f32; 6], left: [f32; 6], right: [f32; 6]) -> Option<Seen> {
        let [vu, _, bu, bv, ..] = centre.map(f64::from);
        let z = self.depth(bv)?;
        let heading_rad = wrap((self.cx - vu).atan2(self.focal_px));
        let y = (self.cx - bu) * z / self.focal_px;
        let (s, c) = heading_rad.sin_cos();
        let offset_m = -c * y + s * z;
        let lateral = |e: [f32; 6]| {
            let [u, v, angle] = [e[0], e[1], e[2]].map(f64::from);
            let sa = angle.sin();
            let x = if sa.abs() < 1e-6 { u } else { u + (bv - v) * angle.cos() / sa };
            (self.cx - x) * z / self.focal_px
        };
        let width_m = (lateral(left) - lateral(right)).abs() * c.abs();
        Some(Seen { heading_rad, offset_m, width_m })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view() -> View {
        View { focal_px: 554.0, cx: 320.0, cy: 240.0, height_m: 1.2 }
    }

    #[test]
    fn a_predicted_path_is_seen_back_where_it_is() {
        // A 3 m path along x; the robot 0.4 m left of its middle, heading 5 degrees to the right.
        let s = Segment::between([[0.0, 1.5], [30.0, 1.5]], [[0.0, -1.5], [30.0, -1.5]]);
        assert!((s.width_m - 3.0).abs() < 1e-9 && s.heading().abs() < 1e-12);
        let at = Pose2::new(4.0, 0.4, -5f64.to_radians());
        let (top, bottom) = (260.0, 479.0);
        let [lt, lb, rt, rb] = view().predict(&s, at, top, bottom).expect("in view");
        // The edges as the worker reports them (a point and a direction), the centreline through
        // their crossing and the middle of the bottom row.
        let line = |a: [f64; 2], b: [f64; 2]| [a[0], a[1], (b[1] - a[1]).atan2(b[0] - a[0]), 0.0, 0.0, 0.0];
        let (l, r) = (line([lt, top], [lb, bottom]), line([rt, top], [rb, bottom]));
        // Both edges cross at the vanishing point: 5 degrees left of the axis, on the horizon.
        let vu = 320.0 - 554.0 * 5f64.to_radians().tan();
        let to32 = |a: [f64; 6]| a.map(|x| x as f32);
        let centre = to32([vu, 240.0, (lb + rb) / 2.0, bottom, 100.0, 0.0]);
        let seen = view().seen(centre, to32(l), to32(r)).expect("seen");
        assert!((seen.heading_rad - 5f64.to_radians()).abs() < 1e-4, "{seen:?}");
        assert!((seen.offset_m - 0.4).abs() < 1e-3, "{seen:?}");
        assert!((seen.width_m - 3.0).abs() < 1e-3, "{seen:?}");
        assert_eq!(s.local([10.0, 0.4]), (10.0, 0.4));
    }
}
