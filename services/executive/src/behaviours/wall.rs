//! A wall beside the robot as the sonar ring's side sensor sees it (001 §3.2): the line fitted
//! to the recent echoes (the robot's pose and the range it read, each the wall's perpendicular
//! distance, the beam echoing from the wall's nearest point), its outliers (crosstalk,
//! multipath) edited out, and the distance and direction a wall follower steers by.

use std::collections::VecDeque;

use harvey_geometry::wrap;
use harvey_msgs::Pose2;

/// One reading: where the robot was and how far the wall was from its centre (m).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Sample {
    at: [f64; 2],
    /// Distance travelled (odometry, m) when it was read.
    travelled_m: f64,
    distance_m: f64,
}

/// The wall as a line `n · q = c`, `n` the unit normal from the robot towards the wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// The normal's angle (world frame, rad) and the offset (m).
    pub normal_rad: f64,
    pub c_m: f64,
}

impl Line {
    /// The line through a point `distance_m` from `at` along the normal `normal_rad`.
    pub fn seen_from(at: [f64; 2], normal_rad: f64, distance_m: f64) -> Self {
        Self { normal_rad, c_m: distance_m + normal_rad.cos() * at[0] + normal_rad.sin() * at[1] }
    }

    /// The wall's perpendicular distance from `at` (m).
    pub fn distance(&self, at: [f64; 2]) -> f64 {
        self.c_m - self.normal_rad.cos() * at[0] - self.normal_rad.sin() * at[1]
    }

    /// The direction along the wall with the wall on side `side` (+1 left, -1 right).
    pub fn along(&self, side: f64) -> f64 {
        wrap(self.normal_rad - side * std::f64::consts::FRAC_PI_2)
    }
}

/// The recent wall readings and the line they give.
#[derive(Debug, Clone)]
pub struct Wall {
    samples: VecDeque<Sample>,
    /// The line used until the readings span enough of the wall to fit one.
    pub line: Line,
    /// Readings over this much travel are fitted; a fit needs them to span `min_span_m`; a
    /// reading further than `gate_m` off the fit is edited out, and further than `loose_m` off
    /// the line before its first fit (a line from one look may be some degrees out).
    window_m: f64,
    min_span_m: f64,
    gate_m: f64,
    loose_m: f64,
    fitted: bool,
}

impl Wall {
    pub fn new(line: Line, window_m: f64, (gate_m, loose_m): (f64, f64)) -> Self {
        Self {
            samples: VecDeque::new(),
            line,
            window_m,
            min_span_m: window_m / 3.0,
            gate_m,
            loose_m: loose_m.max(gate_m),
            fitted: false,
        }
    }

    /// Takes a line from a look (not yet fitted).
    pub fn set(&mut self, line: Line) {
        (self.line, self.fitted) = (line, false);
        self.samples.clear();
    }

    /// Forgets the readings (the wall seen again after an opening is fitted afresh, perhaps a
    /// little in or out), keeping the line until a new fit.
    pub fn restart(&mut self) {
        self.samples.clear();
        self.fitted = false;
    }

    /// Whether a range `distance_m` read at `at` fits the wall as known (within the gate, or
    /// the loose gate before a fit).
    pub fn fits(&self, at: [f64; 2], distance_m: f64) -> bool {
        let gate = if self.fitted { self.gate_m } else { self.loose_m };
        (distance_m - self.line.distance(at)).abs() <= gate
    }

    /// Takes a reading of the wall and fits the line again from the window's readings.
    pub fn add(&mut self, at: [f64; 2], travelled_m: f64, distance_m: f64) {
        self.samples.push_back(Sample { at, travelled_m, distance_m });
        while self.samples.front().is_some_and(|s| travelled_m - s.travelled_m > self.window_m) {
            self.samples.pop_front();
        }
        let span = self.samples.front().map_or(0.0, |s| travelled_m - s.travelled_m);
        if span < self.min_span_m || self.samples.len() < 5 {
            return;
        }
        let mut line = self.line;
        let mut kept: Vec<Sample> = self.samples.iter().copied().collect();
        for _ in 0..3 {
            let Some(fitted) = fit(&kept, line.normal_rad) else { return };
            line = fitted;
            kept.retain(|s| (s.distance_m - line.distance(s.at)).abs() <= self.gate_m);
        }
        if kept.len() >= 5 {
            self.line = fit(&kept, line.normal_rad).unwrap_or(line);
            self.fitted = true;
        }
    }
}

/// Least squares for the line `n(ψ) · q = c` through readings `D = c - n · p`, linearised about
/// the normal (from `normal_rad`, twice) with the positions taken from their centroid: none when
/// the readings do not span the wall.
fn fit(samples: &[Sample], normal_rad: f64) -> Option<Line> {
    let k = samples.len() as f64;
    let centre = samples.iter().fold([0.0, 0.0], |a, s| [a[0] + s.at[0] / k, a[1] + s.at[1] / k]);
    let rel = |s: &Sample| [s.at[0] - centre[0], s.at[1] - centre[1]];
    let mut psi = normal_rad;
    for _ in 0..2 {
        let (n, t) = ([psi.cos(), psi.sin()], [-psi.sin(), psi.cos()]);
        // D + n·p = c - δ (t·p) for the normal turned by δ: y against x, slope -δ.
        let pts: Vec<(f64, f64)> = samples
            .iter()
            .map(|s| {
                let p = rel(s);
                (t[0] * p[0] + t[1] * p[1], s.distance_m + n[0] * p[0] + n[1] * p[1])
            })
            .collect();
        let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / k, pts.iter().map(|p| p.1).sum::<f64>() / k);
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        if sxx < 1e-4 {
            return None;
        }
        psi = wrap(psi + (-sxy / sxx).atan());
    }
    let n = [psi.cos(), psi.sin()];
    let c_rel = samples.iter().map(|s| s.distance_m + n[0] * rel(s)[0] + n[1] * rel(s)[1]).sum::<f64>() / k;
    Some(Line { normal_rad: psi, c_m: c_rel + n[0] * centre[0] + n[1] * centre[1] })
}

/// The heading a follower keeping `keep_m` from the wall steers for at `at`: along the wall,
/// turned towards it when too far and away when too near, `gain` radians per metre off,
/// at most `max_rad`.
pub fn steer(line: &Line, at: Pose2, side: f64, keep_m: f64, gain: f64, max_rad: f64) -> f64 {
    let off = line.distance([at.x_m, at.y_m]) - keep_m;
    wrap(line.along(side) + side * (gain * off).clamp(-max_rad, max_rad))
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_geometry::Rng;

    #[test]
    fn a_line_gives_distance_and_direction() {
        // The wall y = 1 on the left of a robot going +x.
        let l = Line::seen_from([0.0, 0.0], std::f64::consts::FRAC_PI_2, 1.0);
        assert!((l.distance([3.0, 0.4]) - 0.6).abs() < 1e-12);
        assert!(l.along(1.0).abs() < 1e-12);
        // Too far: steer towards the wall (left, positive); too near: away.
        let at = |y| Pose2 { x_m: 0.0, y_m: y, heading_rad: 0.0 };
        assert!(steer(&l, at(0.0), 1.0, 0.5, 1.0, 0.3) > 0.29);
        assert!(steer(&l, at(0.7), 1.0, 0.5, 1.0, 0.3) < -0.19);
        // The wall y = -1 on the right.
        let r = Line::seen_from([0.0, 0.0], -std::f64::consts::FRAC_PI_2, 1.0);
        assert!(r.along(-1.0).abs() < 1e-12 && steer(&r, at(0.0), -1.0, 0.5, 1.0, 0.3) < -0.29);
    }

    #[test]
    fn the_fit_finds_a_slanted_wall_through_noise_and_outliers() {
        // A wall at 5 degrees to the robot's path, 0.8 m off at the start; 2 cm noise; every
        // tenth reading a crosstalk echo 0.4 m short.
        let tilt = 5f64.to_radians();
        let truth = Line { normal_rad: std::f64::consts::FRAC_PI_2 + tilt, c_m: 0.8 };
        let mut wall =
            Wall::new(Line::seen_from([0.0, 0.0], std::f64::consts::FRAC_PI_2, 0.8), 1.0, (0.05, 0.05));
        let mut rng = Rng::new(4);
        for k in 0..60 {
            let at = [0.03 * f64::from(k), 0.0];
            let outlier = if k % 10 == 9 { -0.4 } else { 0.0 };
            wall.add(at, at[0], truth.distance(at) + rng.normal(0.0, 0.02) + outlier);
        }
        let l = wall.line;
        assert!(
            (l.normal_rad - truth.normal_rad).abs() < 1.5f64.to_radians(),
            "{}",
            l.normal_rad.to_degrees()
        );
        let here = [1.77, 0.0];
        assert!(
            (l.distance(here) - truth.distance(here)).abs() < 0.02,
            "{} {}",
            l.distance(here),
            truth.distance(here)
        );
        assert!(wall.fits(here, truth.distance(here)) && !wall.fits(here, truth.distance(here) + 0.5));
    }

    #[test]
    fn too_short_a_span_keeps_the_line_as_it_was() {
        let prior = Line::seen_from([0.0, 0.0], 1.5, 0.7);
        let mut wall = Wall::new(prior, 1.0, (0.05, 0.3));
        for k in 0..20 {
            wall.add([0.01 * f64::from(k), 0.0], 0.01 * f64::from(k), 0.9);
        }
        assert_eq!(wall.line, prior);
    }
}
