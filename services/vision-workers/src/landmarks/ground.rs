//! Recognising a class III landmark (002 §3.4: a ground line) in the Expecter's window: a wall's
//! foot with its baseboard, or a floor edge where two floors meet (a path's edge on its lawn).
//! The map (`band.rs`) gives the edge's height below the camera (a band's top, or the floor) and
//! which way it steps going down an image column (a band darker than the wall above it; for a
//! floor edge, the near floor's reflectance less the far one's). The edge is the straight image
//! line (below the horizon) along which the step of that sign going down the columns, summed,
//! stands out most (`harvey_vision::step_line`: a faint edge no column shows alone is found so),
//! and each column's own strongest step near it an edge point; each edge point is projected
//! onto the plane of the edge's height, giving points on the floor plan in the robot's frame; a
//! line fitted to them with its outliers trimmed (a doorway, a tile's edge) gives the robot's
//! heading relative to the line and its signed distance from it (left positive). The robot is
//! taken to head along the line's direction (its first end to its second) within 90 degrees:
//! the landmark's view headings say so. So a line seen on the left (the window's middle left of
//! the image's) has the robot on its right, which is the near side of a floor edge; and its
//! image then descends to the left.

use harvey_msgs::{Expectation, FrameHeader, Header, LandmarkSighting, SightingKind};
use harvey_vision::levels::{histogram, percentile};
use harvey_vision::noise::noise_sigma;
use harvey_vision::step_line::{HALF_ROWS, MAX_ANGLE, Profiles};
use harvey_vision::{Gray, Rect};
use harvey_world::World;

use super::band::Band;

/// The edge's line counts when its step summed along it is this many times what noise summed over
/// as many columns would reach (`step_line.rs`), and its mean step this fraction of the window's
/// median grey; a column's own edge then counts within `BAND_ROWS` of the line when its step
/// (three rows' means either side) is this many noise deviations and that fraction past nothing.
const MIN_Z: f32 = 8.0;
const MIN_STEP: f32 = 0.15;
const BAND_ROWS: f32 = 3.0;
const NEAR_SIGMAS: f32 = 1.5;
/// A window with fewer rows within `MAX_DEPTH_M` than this shows too little of the floor for a
/// line: in a strip of a few rows at the far limit any stretch of texture sums to one.
const MIN_ROWS: usize = 16;
/// A line further than this from the robot's heading (rad) runs across the view, where a path's
/// joints across it and the far floors' edges are as likely as the line looked for: the robot
/// heads along its line (the landmark's view headings).
const MAX_HEADING_RAD: f64 = std::f64::consts::FRAC_PI_3;
/// A fit whose offset at the robot is known no better than this (m, its own spread and its
/// slope's carried to the points' mean depth) is a stretch of texture or a far floor's edge
/// rather than the line: the edges found within reach are known to a few centimetres.
const MAX_SPREAD_M: f64 = 0.2;
/// Lines tried, best first, until one's points give a fit.
const LINES_TRIED: usize = 3;
/// Columns looked at: every second one.
const COLUMN_STEP: usize = 2;
/// A fit needs this many points over this much depth (m), nearer than `MAX_DEPTH_M`; a point off
/// the fit by more than both `TRIM_M` and three median deviations is trimmed.
const MIN_POINTS: usize = 8;
const MIN_SPAN_M: f64 = 0.5;
const MAX_DEPTH_M: f64 = 12.0;
const TRIM_M: f64 = 0.05;

/// The class III recogniser.
#[derive(Debug)]
pub struct GroundLines {
    bands: Vec<Option<Band>>,
    pub focal_px: f64,
    /// How well the mount's yaw and pitch are known (rad).
    calibration_sd_rad: f64,
    points: Vec<[f64; 2]>,
    profiles: Profiles,
    scratch: Vec<(f32, u32)>,
    spread: Vec<f32>,
}

impl GroundLines {
    pub fn new(world: &World, calibration_sd_rad: f64) -> Self {
        Self {
            bands: Band::of(world),
            focal_px: world.camera.focal_px,
            calibration_sd_rad,
            points: Vec::new(),
            profiles: Profiles::default(),
            scratch: Vec::new(),
            spread: Vec::new(),
        }
    }

    /// Looks for the class III landmark of `e` in a mono8 frame; the sighting's `seq` is left for
    /// the caller to number. `None`: not a class III landmark along a band or a floor edge, or a
    /// window off the frame or of another size.
    pub fn recognise(&mut self, h: &FrameHeader, pixels: &[u8], e: &Expectation) -> Option<LandmarkSighting> {
        let band = *self.bands.get(e.landmark_index as usize)?.as_ref()?;
        let (w, ht) = (h.width_px as usize, h.height_px as usize);
        if e.class != 3 || (e.width_px, e.height_px) != (h.width_px, h.height_px) {
            return None;
        }
        let img = Gray::new(pixels, w, ht, h.stride_bytes as usize).ok()?;
        let [u0, v0, u1, v1] = e.window_px.map(|x| x.max(0.0) as usize);
        let (cx, cy, f) = (w as f64 / 2.0, ht as f64 / 2.0, self.focal_px);
        // Below the horizon only: the band's edge lies under the camera.
        let top = v0.max(cy as usize + 3);
        let win = Rect::new(u0, top, u1.min(w), v1.min(ht)).inside(w, ht).ok()?;
        let base = LandmarkSighting {
            header: Header::new(0, h.stamp_ns),
            frame_seq: h.seq,
            landmark_index: e.landmark_index,
            ..Default::default()
        };
        let not_found = LandmarkSighting { kind: SightingKind::NotFound as u32, ..base };
        // And no higher than where the edge lies `MAX_DEPTH_M` off: a further edge gives no points.
        let nearest_row = cy + f * band.below_camera_m / MAX_DEPTH_M;
        let top = top.max((nearest_row as usize).saturating_sub(HALF_ROWS));
        let Ok(win) = Rect::new(u0, top, win.x1, win.y1).inside(w, ht) else { return Some(not_found) };
        if win.height() < MIN_ROWS {
            return Some(not_found);
        }
        let median = f32::from(percentile(&histogram(&img, win), 0.5));
        let noise = noise_sigma(&img, win);
        // The edge is a straight line in the image: the line whose summed step stands out of the
        // noise, then each column's own step near it. A line seen on the left (the window's
        // middle left of the image's) is taken to have the robot on its right, which says which
        // floor of a floor edge is near (going down a column is coming nearer along the floor).
        // A line descending to the left in the image has the robot on its right, one descending
        // to the right on its left (towards its far end, its vanishing point, it rises): lines
        // of the other slope are not it (a parallel edge of the other sign, looked at from
        // where the guess of side is wrong).
        let robot_right = ((win.x0 + win.x1) as f64) / 2.0 < cx;
        let slopes = if robot_right { (-MAX_ANGLE, 0.0) } else { (0.0, MAX_ANGLE) };
        self.profiles.measure(&img, win, COLUMN_STEP, band.darker_below(robot_right));
        let spread = self.profiles.spread(&mut self.spread);
        let least = (NEAR_SIGMAS * noise).max(MIN_STEP * median);
        let mut fit = None;
        // The best line may be another straight edge of the same sign (where a path's concrete
        // meets its gravel, across it): one whose points give no fit is set aside for the next.
        for _ in 0..LINES_TRIED {
            let line = self.profiles.best_line(slopes, &mut self.scratch);
            let Some(line) =
                line.filter(|l| l.z(spread) >= MIN_Z && l.sum >= MIN_STEP * median * l.columns as f32)
            else {
                break;
            };
            self.points.clear();
            for (c, &u) in self.profiles.columns.iter().enumerate() {
                let Some(row) = self.profiles.peak_near(c, &line.line, BAND_ROWS, least) else { continue };
                let depth = f * band.below_camera_m / (row - cy);
                if depth > 0.0 && depth < MAX_DEPTH_M {
                    self.points.push([depth, depth * (cx - (u as f64 + 0.5)) / f]);
                }
            }
            fit = fit_trimmed(&mut self.points);
            if fit.is_some() {
                break;
            }
            self.profiles.suppress(&line.line, BAND_ROWS);
        }
        let plausible =
            |f: &Fit| f.b.atan().abs() <= MAX_HEADING_RAD && f.a_sd.hypot(f.b_sd * f.mean_x) <= MAX_SPREAD_M;
        let Some(fit) = fit.filter(plausible) else { return Some(not_found) };
        // The line y = a + b x in the robot's frame, along +x: the robot's heading less the
        // line's direction is -atan b; its distance from the line, left positive, -a / |(1, b)|.
        let norm = fit.b.hypot(1.0);
        let heading = -fit.b.atan();
        let offset = -fit.a / norm;
        // An unknown pitch (or an edge placed half a row off all along) moves every row alike,
        // scaling each point's distance by (sd + 0.5 / f) x / h: a line at distance y turns by
        // y (sd + 0.5 / f) / h, and is extrapolated to the robot a little off (kept at the
        // points' mean depth's scale, to be safe). An unknown yaw turns the line.
        let row = self.calibration_sd_rad + 0.5 / f;
        let turn = offset.abs() * row / band.below_camera_m;
        Some(LandmarkSighting {
            kind: SightingKind::GroundLine as u32,
            a: heading,
            a_sd: fit.b_sd.hypot(self.calibration_sd_rad).hypot(turn),
            b: offset,
            // The edge's height off by the map's error (a floor edge's: the camera's height over
            // the floor, known to the survey's accuracy) scales every distance alike.
            b_sd: fit
                .a_sd
                .hypot(turn * fit.mean_x)
                .hypot(offset.abs() * band.height_sd_m / band.below_camera_m),
            ..base
        })
    }
}

/// A line `y = a + b x` and its spreads, and the points' mean depth.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Fit {
    a: f64,
    b: f64,
    a_sd: f64,
    b_sd: f64,
    mean_x: f64,
}

/// The line through two of the points (one from the nearer half, one from the further) that the
/// most points lie within `TRIM_M` of: a doorway's or a tile's edges can outnumber the line's
/// near a doorway, but they do not line up with each other.
fn consensus(points: &[[f64; 2]]) -> Option<(f64, f64)> {
    let mut sorted: Vec<[f64; 2]> = points.to_vec();
    sorted.sort_by(|p, q| p[0].total_cmp(&q[0]));
    let (near, far) = sorted.split_at(sorted.len() / 2);
    let mut best: Option<(usize, f64, (f64, f64))> = None;
    for p in near {
        for q in far.iter().filter(|q| q[0] - p[0] > MIN_SPAN_M / 2.0) {
            let b = (q[1] - p[1]) / (q[0] - p[0]);
            let a = p[1] - b * p[0];
            let (count, spread) = points
                .iter()
                .map(|r| (r[1] - a - b * r[0]).abs())
                .filter(|&e| e <= TRIM_M)
                .fold((0, 0.0), |(n, s), e| (n + 1, s + e));
            if best.is_none_or(|(n, s, _)| count > n || (count == n && spread < s)) {
                best = Some((count, spread, (a, b)));
            }
        }
    }
    best.map(|(_, _, line)| line)
}

/// Least squares on the consensus line's points, then with the points further than both `TRIM_M`
/// and three median deviations from the fit trimmed, three times; none without enough points over
/// enough depth.
fn fit_trimmed(points: &mut Vec<[f64; 2]>) -> Option<Fit> {
    let (a, b) = consensus(points)?;
    points.retain(|p| (p[1] - a - b * p[0]).abs() <= TRIM_M);
    let mut fit = least_squares(points)?;
    for _ in 0..3 {
        let mut r: Vec<f64> = points.iter().map(|p| (p[1] - fit.a - fit.b * p[0]).abs()).collect();
        r.sort_by(f64::total_cmp);
        let gate = (3.0 * 1.4826 * r[r.len() / 2]).max(TRIM_M);
        points.retain(|p| (p[1] - fit.a - fit.b * p[0]).abs() <= gate);
        fit = least_squares(points)?;
    }
    Some(fit)
}

fn least_squares(points: &[[f64; 2]]) -> Option<Fit> {
    let n = points.len();
    if n < MIN_POINTS {
        return None;
    }
    let k = n as f64;
    let (mx, my) =
        (points.iter().map(|p| p[0]).sum::<f64>() / k, points.iter().map(|p| p[1]).sum::<f64>() / k);
    let sxx: f64 = points.iter().map(|p| (p[0] - mx).powi(2)).sum();
    let (lo, hi) =
        points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| (a.0.min(p[0]), a.1.max(p[0])));
    if hi - lo < MIN_SPAN_M || sxx <= 0.0 {
        return None;
    }
    let b = points.iter().map(|p| (p[0] - mx) * (p[1] - my)).sum::<f64>() / sxx;
    let a = my - b * mx;
    let res = (points.iter().map(|p| (p[1] - a - b * p[0]).powi(2)).sum::<f64>() / (k - 2.0)).sqrt();
    Some(Fit { a, b, a_sd: res * (1.0 / k + mx * mx / sxx).sqrt(), b_sd: res / sxx.sqrt(), mean_x: mx })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::landmarks::band::Edge;

    #[test]
    fn the_hallway_s_baseboard_is_a_band_and_a_line_is_fitted_through_strays() {
        let w = harvey_world::load_str(include_str!("../../../../worlds/hallway.toml"), "hallway")
            .expect("world");
        let bands = Band::of(&w);
        let i = w.landmarks.iter().position(|l| l.name == "north-baseboard").expect("landmark");
        let b = bands[i].expect("the baseboard");
        assert!((b.below_camera_m - (1.2 - 0.12)).abs() < 1e-9 && b.edge == Edge::Baseboard { darker: true });
        assert!(bands.iter().enumerate().all(|(k, x)| k == i || x.is_none()));
        // Points on y = 1 - 0.05 x with two strays.
        let mut pts: Vec<[f64; 2]> =
            (0..20).map(|k| f64::from(k) * 0.3 + 1.0).map(|x| [x, 1.0 - 0.05 * x]).collect();
        pts.extend([[2.0, 0.4], [3.0, 1.8]]);
        let fit = fit_trimmed(&mut pts).expect("fits");
        assert!((fit.a - 1.0).abs() < 1e-9 && (fit.b + 0.05).abs() < 1e-9, "{fit:?}");
        assert_eq!(pts.len(), 20);
    }
}
