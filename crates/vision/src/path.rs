//! Path following with the line finder (001 §2.1): the line fragments near each predicted path
//! edge (close to it, of like orientation, below the vanishing point) are grouped into one edge
//! by the principal axis of their ends, weighted by length and gradient; the
//! two edges give the centreline, and the fragments' total length is the confidence. Each fit
//! is fed forward as the next frame's prediction; when confidence falls short, the tolerances
//! are widened once before the path counts as lost.

use crate::flf::Line;

/// An image line: a point on it and its direction (radians, image x right, y down).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageLine {
    pub point: [f32; 2],
    pub angle: f32,
}

impl ImageLine {
    pub fn through(a: [f32; 2], b: [f32; 2]) -> Self {
        Self { point: a, angle: (b[1] - a[1]).atan2(b[0] - a[0]) }
    }

    /// Perpendicular distance of `p` from the line.
    pub fn distance(&self, p: [f32; 2]) -> f32 {
        let (c, s) = (self.angle.cos(), self.angle.sin());
        ((p[0] - self.point[0]) * s - (p[1] - self.point[1]) * c).abs()
    }

    /// The x where the line crosses row `v`.
    pub fn x_at(&self, v: f32) -> f32 {
        let (c, s) = (self.angle.cos(), self.angle.sin());
        if s.abs() < 1e-6 { self.point[0] } else { self.point[0] + (v - self.point[1]) * c / s }
    }

    /// The y where the line crosses column `u` (a vertical line: its point's y).
    pub fn y_at(&self, u: f32) -> f32 {
        let (c, s) = (self.angle.cos(), self.angle.sin());
        if c.abs() < 1e-6 { self.point[1] } else { self.point[1] + (u - self.point[0]) * s / c }
    }

    /// Where two lines cross.
    pub fn cross(&self, o: &ImageLine) -> Option<[f32; 2]> {
        let (d1, d2) = ([self.angle.cos(), self.angle.sin()], [o.angle.cos(), o.angle.sin()]);
        let den = d1[0] * d2[1] - d1[1] * d2[0];
        if den.abs() < 1e-6 {
            return None;
        }
        let (dx, dy) = (o.point[0] - self.point[0], o.point[1] - self.point[1]);
        let t = (dx * d2[1] - dy * d2[0]) / den;
        Some([self.point[0] + t * d1[0], self.point[1] + t * d1[1]])
    }
}

/// The distance a fragment's middle may lie from its predicted edge at the horizon (pixels).
const MIN_DISTANCE_PX: f32 = 2.0;

/// Tolerances of the grouping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathParams {
    /// A fragment's midpoint within this distance of the predicted edge at the bottom row
    /// (pixels), shrinking with perspective to 2 px at the horizon (a lateral tolerance on the
    /// ground)…
    pub max_distance_px: f32,
    /// …and its direction within this angle of it (radians).
    pub max_angle: f32,
    /// Least total fragment length (pixels) of a confident fit.
    pub min_confidence: f32,
}

/// One frame's path: both edges, the centreline (through the vanishing point and the middle of
/// the path at the image's bottom row), and the confidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathFit {
    pub left: ImageLine,
    pub right: ImageLine,
    pub centreline: ImageLine,
    pub vanishing: [f32; 2],
    /// Total length of the fragments used (pixels).
    pub confidence: f32,
}

/// Groups the fragments of one edge; `None` when none qualifies. A fragment belongs when its
/// middle lies below the horizon within the distance allowed at its row of the predicted edge,
/// and its direction within the angle. The edge is the principal axis of the fragments' ends,
/// each end weighted by half its fragment's length times its mean gradient: the middles of a
/// point-sampled edge's short fragments lie on it even where each fragment's own direction is
/// some degrees off (a staircase of rows), and a weaker line beside it (a tile's joint) counts
/// for less.
fn edge(
    lines: &[Line],
    predicted: &ImageLine,
    (horizon_v, bottom_v): (f32, f32),
    p: &PathParams,
) -> Option<(ImageLine, f32)> {
    let (mut w, mut mx, mut my, mut length) = (0.0, 0.0, 0.0, 0.0);
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    let span = (bottom_v - horizon_v).max(1.0);
    for l in lines {
        let mid = [(l.from[0] + l.to[0]) / 2.0, (l.from[1] + l.to[1]) / 2.0];
        let dir = (l.to[1] - l.from[1]).atan2(l.to[0] - l.from[0]);
        let turn = turn_between(dir, predicted.angle);
        // The ground's lateral tolerance shrinks in the image towards the vanishing point.
        let allowed = MIN_DISTANCE_PX + p.max_distance_px * ((mid[1] - horizon_v) / span).clamp(0.0, 1.0);
        if mid[1] <= horizon_v || turn > p.max_angle || predicted.distance(mid) > allowed {
            continue;
        }
        let k = 0.5 * l.length * l.mean_gradient.max(1.0);
        for e in [l.from, l.to] {
            (w, mx, my) = (w + k, mx + k * e[0], my + k * e[1]);
            (sxx, syy, sxy) = (sxx + k * e[0] * e[0], syy + k * e[1] * e[1], sxy + k * e[0] * e[1]);
        }
        length += l.length;
    }
    if w <= 0.0 {
        return None;
    }
    let (cx, cy) = (mx / w, my / w);
    let (vxx, vyy, vxy) = (sxx / w - cx * cx, syy / w - cy * cy, sxy / w - cx * cy);
    Some((ImageLine { point: [cx, cy], angle: 0.5 * (2.0 * vxy).atan2(vxx - vyy) }, length))
}

/// One grouping of `lines` against the predicted edges, rows above `horizon_v` ignored.
pub fn group(
    lines: &[Line],
    left: &ImageLine,
    right: &ImageLine,
    horizon_v: f32,
    bottom_v: f32,
    p: &PathParams,
) -> Option<PathFit> {
    let (l, wl) = edge(lines, left, (horizon_v, bottom_v), p)?;
    let (r, wr) = edge(lines, right, (horizon_v, bottom_v), p)?;
    let vanishing = l.cross(&r)?;
    let bottom = [(l.x_at(bottom_v) + r.x_at(bottom_v)) / 2.0, bottom_v];
    Some(PathFit {
        left: l,
        right: r,
        centreline: ImageLine::through(vanishing, bottom),
        vanishing,
        confidence: wl + wr,
    })
}

/// Feed-forward tracking of the path from frame to frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PathTracker {
    pub left: ImageLine,
    pub right: ImageLine,
    pub horizon_v: f32,
    pub bottom_v: f32,
    pub params: PathParams,
}

impl PathTracker {
    /// Bootstrap: the edges predicted from the map and the robot's pose (LTM and the spatial
    /// uncertainty map).
    pub fn new(left: ImageLine, right: ImageLine, horizon_v: f32, bottom_v: f32, params: PathParams) -> Self {
        Self { left, right, horizon_v, bottom_v, params }
    }

    /// Update with a frame's lines: group against the prediction; if not confident, once more
    /// with doubled tolerances; a confident fit that follows from the prediction (`follows`)
    /// becomes the next prediction. `None`: lost.
    pub fn update(&mut self, lines: &[Line]) -> Option<PathFit> {
        let p = self.params;
        let wide = PathParams { max_distance_px: 2.0 * p.max_distance_px, max_angle: 2.0 * p.max_angle, ..p };
        let fit = [p, wide].into_iter().find_map(|q| {
            group(lines, &self.left, &self.right, self.horizon_v, self.bottom_v, &q)
                .filter(|f| self.takes(f, &q))
        })?;
        // The vanishing point bounds the fragments of the next frame.
        (self.left, self.right, self.horizon_v) = (fit.left, fit.right, fit.vanishing[1]);
        Some(fit)
    }

    /// Whether `fit` follows from the prediction within the tolerances `q`: each edge of like
    /// direction (the fragments' principal axis can turn far from every fragment's own, when
    /// they scatter), and the vanishing row within `q.max_distance_px` of the last (ground lines
    /// vanish on the horizon, which moves only as the camera pitches: 30 px is some 3 degrees).
    /// A tracker's first `horizon_v` must be that near the frames' horizon: the vision workers
    /// start it at a level camera's.
    pub fn follows(&self, fit: &PathFit, q: &PathParams) -> bool {
        turn_between(fit.left.angle, self.left.angle) <= q.max_angle
            && turn_between(fit.right.angle, self.right.angle) <= q.max_angle
            && (fit.vanishing[1] - self.horizon_v).abs() <= q.max_distance_px
    }

    /// Whether `fit` becomes the next prediction: confident, and following from this one. A fit
    /// whose edges cross below the middle of the rows the path was last seen on is not the path
    /// ahead either (taken as the next prediction, it would shut every fragment out).
    pub(crate) fn takes(&self, fit: &PathFit, q: &PathParams) -> bool {
        let lowest = (self.horizon_v + self.bottom_v) / 2.0;
        fit.confidence >= q.min_confidence && fit.vanishing[1] < lowest && self.follows(fit, q)
    }
}

/// The angle between two image directions, whichever way round each is given (0..=pi/2).
pub fn turn_between(a: f32, b: f32) -> f32 {
    let d = (a - b).rem_euclid(std::f32::consts::PI);
    d.min(std::f32::consts::PI - d)
}
