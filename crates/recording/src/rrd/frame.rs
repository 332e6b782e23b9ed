//! Where the world view looks: the box round the action (the robot, the last metres of its true
//! path, the goal and the plan), the walls clipped to it, which landmarks the camera has in view,
//! and the decimated trails the paths are drawn from. Pure geometry, in world metres.
//!
//! The clip is Liang-Barsky written out here (a dozen lines) rather than parry's shapes, which
//! would need a conversion each way for one segment against one box.

/// An axis-aligned box in world metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub min: [f64; 2],
    pub max: [f64; 2],
}

impl Bounds {
    pub fn around(p: [f64; 2]) -> Self {
        Self { min: p, max: p }
    }

    pub fn include(&mut self, p: [f64; 2]) {
        self.min = [self.min[0].min(p[0]), self.min[1].min(p[1])];
        self.max = [self.max[0].max(p[0]), self.max[1].max(p[1])];
    }

    /// Grown by `margin` on every side, then to at least `min_side` along each axis (centred).
    pub fn framed(mut self, margin: f64, min_side: f64) -> Self {
        for k in 0..2 {
            self.min[k] -= margin;
            self.max[k] += margin;
            let short = min_side - (self.max[k] - self.min[k]);
            if short > 0.0 {
                self.min[k] -= short / 2.0;
                self.max[k] += short / 2.0;
            }
        }
        self
    }

    pub fn contains(&self, p: [f64; 2]) -> bool {
        (0..2).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }

    /// The largest distance any side moved from `other`'s.
    pub fn moved_from(&self, other: &Bounds) -> f64 {
        (0..2)
            .map(|k| (self.min[k] - other.min[k]).abs().max((self.max[k] - other.max[k]).abs()))
            .fold(0.0, f64::max)
    }
}

/// The part of the segment `a`-`b` inside `bounds`, if any.
pub fn clip(a: [f64; 2], b: [f64; 2], bounds: &Bounds) -> Option<([f64; 2], [f64; 2])> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..2 {
        for (p, q) in [(-d[k], a[k] - bounds.min[k]), (d[k], bounds.max[k] - a[k])] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let t = q / p;
                if p < 0.0 { t0 = t0.max(t) } else { t1 = t1.min(t) }
            }
        }
    }
    (t0 <= t1).then(|| ([a[0] + t0 * d[0], a[1] + t0 * d[1]], [a[0] + t1 * d[0], a[1] + t1 * d[1]]))
}

/// Whether `p` lies in the camera's horizontal field of view (half-angle `half_fov_rad`) within
/// `range_m` of the robot at `pose` (x, y, heading).
pub fn in_view(pose: [f64; 3], p: [f64; 2], half_fov_rad: f64, range_m: f64) -> bool {
    let (dx, dy) = (p[0] - pose[0], p[1] - pose[1]);
    let r = dx.hypot(dy);
    let bearing = harvey_geometry::wrap(dy.atan2(dx) - pose[2]);
    r > 1e-6 && r <= range_m && bearing.abs() <= half_fov_rad
}

/// A path drawn as a line: a point kept each time the robot has moved `step_m`, thinned by half
/// once it holds `cap` points, so a long run's trail stays a few thousand points.
#[derive(Debug, Clone)]
pub struct Trail {
    pub points: Vec<[f64; 2]>,
    step_m: f64,
    cap: usize,
}

impl Trail {
    pub fn new(step_m: f64, cap: usize) -> Self {
        Self { points: Vec::new(), step_m, cap }
    }

    /// Adds `p` if it is far enough from the last point kept; says whether it did.
    pub fn push(&mut self, p: [f64; 2]) -> bool {
        if let Some(last) = self.points.last()
            && (p[0] - last[0]).hypot(p[1] - last[1]) < self.step_m
        {
            return false;
        }
        self.points.push(p);
        if self.points.len() > self.cap {
            let last = self.points.len() - 1;
            let kept: Vec<[f64; 2]> = self
                .points
                .iter()
                .enumerate()
                .filter(|(i, _)| i % 2 == 0 || *i == last)
                .map(|(_, p)| *p)
                .collect();
            self.points = kept;
        }
        true
    }

    /// The points within the last `length_m` of travel, newest last.
    pub fn recent(&self, length_m: f64) -> &[[f64; 2]] {
        let mut travelled = 0.0;
        let mut start = self.points.len().saturating_sub(1);
        while start > 0 && travelled < length_m {
            let (a, b) = (self.points[start - 1], self.points[start]);
            travelled += (b[0] - a[0]).hypot(b[1] - a[1]);
            start -= 1;
        }
        &self.points[start..]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wall_crossing_the_box_is_cut_at_its_sides() {
        let b = Bounds { min: [0.0, 0.0], max: [4.0, 2.0] };
        let (p, q) = clip([-1.0, 1.0], [5.0, 1.0], &b).expect("crosses");
        assert_eq!((p, q), ([0.0, 1.0], [4.0, 1.0]));
        let (p, q) = clip([1.0, -1.0], [3.0, 3.0], &b).expect("crosses diagonally");
        assert!((p[0] - 1.5).abs() < 1e-12 && p[1] == 0.0 && (q[0] - 2.5).abs() < 1e-12 && q[1] == 2.0);
        assert_eq!(clip([1.0, 0.5], [2.0, 1.5], &b), Some(([1.0, 0.5], [2.0, 1.5])), "inside: unchanged");
        assert_eq!(clip([-1.0, 3.0], [5.0, 3.0], &b), None, "above the box");
        assert_eq!(clip([5.0, -1.0], [6.0, 3.0], &b), None, "beside the box");
    }

    #[test]
    fn the_frame_has_a_margin_and_a_least_size() {
        let mut b = Bounds::around([1.0, 1.0]);
        b.include([7.0, 1.5]);
        let f = b.framed(1.0, 4.0);
        assert_eq!(f.min[0], 0.0);
        assert_eq!(f.max[0], 8.0);
        assert!((f.max[1] - f.min[1] - 4.0).abs() < 1e-12, "the short side is widened to 4 m");
        assert!((f.min[1] + f.max[1] - 2.5).abs() < 1e-12, "about its centre");
        assert!(f.moved_from(&f) == 0.0 && f.moved_from(&b.framed(1.5, 4.0)) == 0.5);
    }

    #[test]
    fn only_what_lies_ahead_within_the_field_of_view_is_in_view() {
        let half = 30f64.to_radians();
        let pose = [0.0, 0.0, std::f64::consts::FRAC_PI_2];
        assert!(in_view(pose, [0.5, 3.0], half, 10.0));
        assert!(!in_view(pose, [3.0, 3.0], half, 10.0), "45 degrees off");
        assert!(!in_view(pose, [0.0, -3.0], half, 10.0), "behind");
        assert!(!in_view(pose, [0.0, 12.0], half, 10.0), "too far");
    }

    #[test]
    fn a_trail_keeps_a_point_every_step_and_thins_past_its_cap() {
        let mut t = Trail::new(0.05, 8);
        assert!(t.push([0.0, 0.0]));
        assert!(!t.push([0.01, 0.0]), "1 cm is below the step");
        for k in 1..=8 {
            assert!(t.push([0.1 * f64::from(k), 0.0]));
        }
        assert!(t.points.len() <= 8, "thinned: {}", t.points.len());
        assert_eq!(t.points.first(), Some(&[0.0, 0.0]));
        assert_eq!(t.points.last(), Some(&[0.8, 0.0]), "the newest point survives thinning");
        let recent = t.recent(0.3);
        assert!(recent.first().is_some_and(|p| p[0] <= 0.5 + 1e-9) && recent.len() < t.points.len());
    }
}
