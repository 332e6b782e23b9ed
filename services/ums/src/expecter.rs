//! The Expecter (002 §5.1): the image window in which a landmark must appear, given the map —
//! the worst case over the polygon's vertices and the wedge's limits through the camera
//! calibration — widened for the perceptual strategy that will look in it. For comparison, the
//! window a disk model of the same uncertainty gives (002 Fig. 68–69).

use harvey_world::{Camera, Landmark, LandmarkClass, project_with};

use crate::geometry::Pt;
use crate::map::{Map, wrap};

/// An image window in pixels, `[u0, u1) x [v0, v1)`, inside the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    pub u0: f64,
    pub v0: f64,
    pub u1: f64,
    pub v1: f64,
}

impl Window {
    pub fn area_px(&self) -> f64 {
        (self.u1 - self.u0).max(0.0) * (self.v1 - self.v0).max(0.0)
    }

    pub fn contains(&self, p: [f64; 2]) -> bool {
        (self.u0..=self.u1).contains(&p[0]) && (self.v0..=self.v1).contains(&p[1])
    }
}

/// The image and the camera that sees it.
#[derive(Debug, Clone, Copy)]
pub struct View<'c> {
    pub camera: &'c Camera,
    pub width_px: u32,
    pub height_px: u32,
}

/// World points that stand for a landmark in the image: a vertical line's foot and top, a
/// point, or points along a ground line within `reach_m` of `near`.
pub fn feature_points(l: &Landmark, near: Pt, reach_m: f64) -> Vec<[f64; 3]> {
    let p = l.position_m;
    match (l.class, l.to_m) {
        (LandmarkClass::I, _) => vec![p, [p[0], p[1], p[2] + l.height_m]],
        (LandmarkClass::III, Some(q)) => {
            let n = 16;
            (0..=n)
                .map(|k| k as f64 / n as f64)
                .map(|t| [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), 0.0])
                .filter(|x| (x[0] - near[0]).hypot(x[1] - near[1]) <= reach_m)
                .collect()
        }
        _ => vec![p],
    }
}

/// The map's heading wedge, with what [`Wedge::facing`] needs worked out once per window.
struct Wedge {
    lo: f64,
    hi: f64,
    heading: [f64; 2],
    tan_cw: f64,
    tan_ccw: f64,
    /// Both sides under 80 degrees: the cheap test applies.
    narrow: bool,
}

impl Wedge {
    fn new(map: &Map) -> Self {
        let [lo, hi] = map.wedge();
        let side = 0.0..1.4;
        Self {
            lo,
            hi,
            heading: [map.heading_rad.cos(), map.heading_rad.sin()],
            tan_cw: map.cw_rad.tan(),
            tan_ccw: map.ccw_rad.tan(),
            narrow: side.contains(&map.cw_rad) && side.contains(&map.ccw_rad),
        }
    }

    /// The heading facing `target` from `p`, when the wedge holds it: there the target's depth,
    /// and so its image row, peaks. Between it and the wedge's limits a point's image position
    /// moves monotonically, so these headings bound it over the whole wedge. A narrow wedge
    /// first rules out, without an `atan2`, a target clearly outside it (by a millionth of its
    /// distance, far beyond rounding); what is not ruled out gets the exact heading.
    fn facing(&self, map: &Map, p: Pt, target: [f64; 3]) -> Option<f64> {
        let (dx, dy) = (target[0] - p[0], target[1] - p[1]);
        if self.narrow {
            let [c, s] = self.heading;
            let (along, across) = (dx * c + dy * s, dy * c - dx * s);
            let slack = 1e-6 * (dx.abs() + dy.abs());
            if along < -slack
                || across > along * self.tan_ccw + slack
                || across < -along * self.tan_cw - slack
            {
                return None;
            }
        }
        let facing = map.heading_rad + wrap(dy.atan2(dx) - map.heading_rad);
        (self.lo..=self.hi).contains(&facing).then_some(facing)
    }
}

/// The Expecter's window for landmark `l` under `map`: the bounding box of its feature points
/// seen from every polygon vertex at each point's bounding headings, clipped to the image and
/// widened by `margin_px`; `None` if nothing projects into view.
pub fn window(map: &Map, view: View<'_>, l: &Landmark, margin_px: f64) -> Option<Window> {
    let points = feature_points(l, map.centre, l.activation_range_m);
    let m = view.camera.calibration(view.width_px, view.height_px);
    // The wedge's limits are the same for every vertex and point: their sines once.
    let wedge = Wedge::new(map);
    let limits = [wedge.lo, wedge.hi].map(|th| {
        let (s, c) = th.sin_cos();
        [c, s]
    });
    let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    let mut grow = |p: &Pt, [c, s]: [f64; 2], x: [f64; 3]| {
        if let Some([u, v]) = project_with(&m, [p[0], p[1], c, s], x) {
            b = [b[0].min(u), b[1].min(v), b[2].max(u), b[3].max(v)];
        }
    };
    for p in &map.polygon {
        for x in &points {
            for limit in limits {
                grow(p, limit, *x);
            }
            if let Some(th) = wedge.facing(map, *p, *x) {
                let (s, c) = th.sin_cos();
                grow(p, [c, s], *x);
            }
        }
    }
    let (w, h) = (f64::from(view.width_px), f64::from(view.height_px));
    let win = Window {
        u0: (b[0] - margin_px).max(0.0),
        v0: (b[1] - margin_px).max(0.0),
        u1: (b[2] + margin_px).min(w),
        v1: (b[3] + margin_px).min(h),
    };
    (b[0].is_finite() && win.u0 < win.u1 && win.v0 < win.v1).then_some(win)
}

/// The Expecter's window for the frame the vision workers will search it in, one tick after the
/// odometry the map was grown from: the union of the windows from the map now and from the map
/// moved on by the last tick's motion (`turn_rad`, then `run_m` along the heading) once more. A
/// turn at 30 deg/s moves a landmark some 15 px in a 50 ms tick, more than the margins.
pub fn window_ahead(
    map: &Map,
    view: View<'_>,
    l: &Landmark,
    margin_px: f64,
    (turn_rad, run_m): (f64, f64),
) -> Option<Window> {
    let now = window(map, view, l, margin_px);
    if turn_rad == 0.0 && run_m == 0.0 {
        return now;
    }
    let mut next = map.clone();
    next.heading_rad += turn_rad;
    let (dx, dy) = (run_m * next.heading_rad.cos(), run_m * next.heading_rad.sin());
    for p in next.polygon.iter_mut().chain(std::iter::once(&mut next.centre)) {
        (p[0], p[1]) = (p[0] + dx, p[1] + dy);
    }
    match (now, window(&next, view, l, margin_px)) {
        (Some(a), Some(b)) => {
            Some(Window { u0: a.u0.min(b.u0), v0: a.v0.min(b.v0), u1: a.u1.max(b.u1), v1: a.v1.max(b.v1) })
        }
        (a, b) => a.or(b),
    }
}

/// The window a disk of the same uncertainty (centred on the map's centre, reaching its
/// farthest vertex) would give: the model 002 §3.1 argues against.
pub fn disk_window(map: &Map, view: View<'_>, l: &Landmark, margin_px: f64) -> Option<Window> {
    let c = map.centre;
    let r = map.polygon.iter().map(|p| (p[0] - c[0]).hypot(p[1] - c[1])).fold(0.0, f64::max);
    let disk: Vec<Pt> = (0..72)
        .map(|k| k as f64 * std::f64::consts::TAU / 72.0)
        .map(|a| [c[0] + r * a.cos(), c[1] + r * a.sin()])
        .collect();
    let as_map = Map { polygon: disk, ..map.clone() };
    window(&as_map, view, l, margin_px)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_covers_where_the_landmark_will_be_a_tick_into_a_turn() {
        let w =
            harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("hallway");
        let l = w.landmarks.iter().find(|l| l.name == "end-wall-corner").expect("landmark");
        let view = View { camera: &w.camera, width_px: 640, height_px: 480 };
        let map = Map::exact(0.0, 0.0, 0.0);
        // Turning left at 30 deg/s: 1.5 degrees a 50 ms tick.
        let turn = 1.5f64.to_radians();
        let now = window(&map, view, l, 4.0).expect("in view");
        let ahead = window_ahead(&map, view, l, 4.0, (turn, 0.0)).expect("in view");
        let m = w.camera.calibration(640, 480);
        let foot = project_with(&m, [0.0, 0.0, turn.cos(), turn.sin()], l.position_m).expect("in front");
        assert!(!now.contains(foot), "the map's own window misses it: {now:?} {foot:?}");
        assert!(ahead.contains(foot), "{ahead:?} {foot:?}");
        assert!(ahead.u0 <= now.u0 && ahead.u1 >= now.u1 && ahead.v0 <= now.v0 && ahead.v1 >= now.v1);
        // Standing still: the same window.
        assert_eq!(window_ahead(&map, view, l, 4.0, (0.0, 0.0)), Some(now));
    }

    #[test]
    fn the_quick_wedge_test_agrees_with_the_exact_heading_everywhere() {
        // Targets all round a vertex, some on and just beside the wedge's limits, for narrow
        // wedges (the quick test) and wide ones (exact only), headings all round the turn.
        let exact = |map: &Map, p: Pt, t: [f64; 3]| {
            let [lo, hi] = map.wedge();
            let facing = map.heading_rad + wrap((t[1] - p[1]).atan2(t[0] - p[0]) - map.heading_rad);
            (lo..=hi).contains(&facing).then_some(facing)
        };
        let mut inside = 0;
        for heading in (-8..=8).map(|k| f64::from(k) * 0.4) {
            for (cw, ccw) in [(0.0, 0.0), (0.02, 0.05), (0.3, 0.1), (1.2, 1.3), (1.5, 0.2), (2.0, 2.5)] {
                let map = Map { cw_rad: cw, ccw_rad: ccw, ..Map::exact(1.0, -2.0, heading) };
                let wedge = Wedge::new(&map);
                let p = [1.5, -1.0];
                let limits = [heading - cw, heading + ccw];
                let offsets = (-40..=40)
                    .map(|k| f64::from(k) * 0.05)
                    .chain(limits.iter().flat_map(|l| [-1e-9, 0.0, 1e-9].map(|d| l - heading + d)));
                for a in offsets {
                    for r in [0.3, 4.0, 25.0] {
                        let t = [p[0] + r * (heading + a).cos(), p[1] + r * (heading + a).sin(), 1.0];
                        let (quick, sure) = (wedge.facing(&map, p, t), exact(&map, p, t));
                        assert_eq!(quick, sure, "heading {heading} wedge -{cw}/+{ccw} at {a} x {r} m");
                        inside += usize::from(sure.is_some());
                    }
                }
            }
        }
        assert!(inside > 500, "the grid reaches inside the wedges: {inside}");
    }
}
