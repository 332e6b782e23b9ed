//! Depth from motion along a known translation (001 §2.3, after Bharwani, Riseman and Hanson),
//! and obstacle extraction.
//!
//! The camera translates along its axis, so a static point moves radially away from the focus
//! of expansion (FOE). At image distance `r` from the FOE after a travel `T`, `1/r` is linear
//! in `T`: `1/r = (Z0 - T) / (f R)`. Start-up finds Moravec points and their first match;
//! each update predicts where a point must be from its depth so far, matches it by correlation
//! in a small window on its radial line, and refits the line by weighted least squares (weights
//! from the pixel noise), so the depth and its standard deviation sharpen frame by frame at a
//! constant cost per point. Obstacles: ground points satisfy `v - v0 = f h / Z`, a straight line
//! in image row against `1/depth`; the fit's outliers above it stand off the floor.

use crate::image::{Gray, GrayBuf, Rect, VisionError};
use crate::moravec::{Moravec, MoravecParams};
use crate::nc::{Correlator, Template};

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthParams {
    /// Focus of expansion (pixels) and focal length (pixels).
    pub foe: [f32; 2],
    pub focal_px: f32,
    /// Side of the patch tracked by correlation (odd).
    pub patch: usize,
    /// Start-up search: how far out along the radial line a point may move (pixels).
    pub startup_reach_px: f32,
    /// Update search: the window round the predicted position (pixels each way).
    pub update_reach_px: f32,
    /// Measurement noise of a matched position (pixels), weighting the fit.
    pub noise_px: f32,
    /// Least correlation score of a kept match.
    pub min_score: f32,
    /// Below this score the patch is cut afresh from the current frame.
    pub recut_score: f32,
    pub moravec: MoravecParams,
}

/// One tracked point.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// Its number at start-up.
    pub id: usize,
    /// Image position now.
    pub at: [f32; 2],
    /// Depth now along the optical axis (m) and its standard deviation; `None` before two frames.
    pub depth: Option<(f32, f32)>,
    /// Frames it has been matched in.
    pub frames: usize,
    /// Sums of the weighted fit of `1/r` against travel: Σw, ΣwT, ΣwT², Σw/r, ΣwT/r.
    sums: [f64; 5],
    patch: GrayBuf,
    /// Where the point was when the patch was cut.
    patch_at: [f32; 2],
    lost: bool,
}

/// The tracker.
#[derive(Debug)]
pub struct DepthFromMotion {
    pub params: DepthParams,
    tracks: Vec<Track>,
    moravec: Moravec,
    correlator: Correlator,
    template: Option<Template>,
    travelled_m: f64,
}

impl DepthFromMotion {
    pub fn new(params: DepthParams) -> Self {
        Self {
            params,
            tracks: Vec::new(),
            moravec: Moravec::default(),
            correlator: Correlator::default(),
            template: None,
            travelled_m: 0.0,
        }
    }

    pub fn tracks(&self) -> impl Iterator<Item = &Track> {
        self.tracks.iter().filter(|t| !t.lost)
    }

    /// Start-up: interesting points of `window` in the first frame, taken at travel `travelled_m`.
    pub fn start(&mut self, img: &Gray<'_>, window: Rect, travelled_m: f64) -> Result<usize, VisionError> {
        let p = self.params;
        if p.patch.is_multiple_of(2) || p.patch < 5 {
            return Err(VisionError::BadParameter(format!("patch {} must be odd and at least 5", p.patch)));
        }
        let half = p.patch / 2;
        self.tracks.clear();
        self.travelled_m = travelled_m;
        for c in self.moravec.corners(img, window, &p.moravec)? {
            let (x, y) = (c.x, c.y);
            if x < half || y < half || x + half >= img.width || y + half >= img.height {
                continue;
            }
            let at = [x as f32 + 0.5, y as f32 + 0.5];
            let id = self.tracks.len();
            let patch = GrayBuf::default();
            let mut t =
                Track { id, at, depth: None, frames: 1, sums: [0.0; 5], patch, patch_at: at, lost: false };
            add_sample(&mut t.sums, &p, at, travelled_m);
            t.patch = cut(img, x, y, half)?;
            self.tracks.push(t);
        }
        Ok(self.tracks.len())
    }

    /// Update: the next frame, taken at travel `travelled_m` (metres along the axis since any
    /// fixed origin). Returns how many points are still tracked.
    pub fn update(&mut self, img: &Gray<'_>, travelled_m: f64) -> Result<usize, VisionError> {
        let p = self.params;
        let step = travelled_m - self.travelled_m;
        if step.is_nan() || step <= 0.0 {
            return Err(VisionError::BadParameter(format!(
                "travel must grow: {} after {}",
                travelled_m, self.travelled_m
            )));
        }
        self.travelled_m = travelled_m;
        let half = p.patch / 2;
        for t in self.tracks.iter_mut().filter(|t| !t.lost) {
            let (d, r) = radial(&p, t.at);
            // Where the point must be: from its depth, or anywhere out along its ray at start-up.
            let (lo, hi) = match t.depth {
                Some((z, _)) if f64::from(z) > step => {
                    let r_next = r * z / (z - step as f32);
                    (r_next - p.update_reach_px, r_next + p.update_reach_px)
                }
                _ => (r, r + p.startup_reach_px),
            };
            let pt = |rr: f32| [p.foe[0] + d[0] * rr, p.foe[1] + d[1] * rr];
            let (a, b) = (pt(lo.max(0.0)), pt(hi));
            let reach = p.update_reach_px.max(2.0);
            let x0 = a[0].min(b[0]) - reach - half as f32;
            let y0 = a[1].min(b[1]) - reach - half as f32;
            let x1 = a[0].max(b[0]) + reach + half as f32 + 1.0;
            let y1 = a[1].max(b[1]) + reach + half as f32 + 1.0;
            if x0 < 0.0 || y0 < 0.0 || x1 > img.width as f32 || y1 > img.height as f32 {
                t.lost = true;
                continue;
            }
            let win = Rect::new(x0 as usize, y0 as usize, x1 as usize, y1 as usize);
            match &mut self.template {
                Some(tm) => tm.set(&t.patch)?,
                None => self.template = Some(Template::new(&t.patch)?),
            }
            let Some(tm) = self.template.as_ref() else { continue };
            let m = self.correlator.best(img, win, tm)?;
            // The patch was cut centred on the pixel holding the point: keep its offset.
            let pa = t.patch_at;
            let off = [pa[0] - (pa[0] - 0.5).round() - 0.5, pa[1] - (pa[1] - 0.5).round() - 0.5];
            let at = [m.centre[0] + off[0], m.centre[1] + off[1]];
            // A static point stays on its radial line.
            let (_, r_new) = radial(&p, at);
            let across = (at[0] - p.foe[0]) * d[1] - (at[1] - p.foe[1]) * d[0];
            if m.score < p.min_score || across.abs() > 1.5 || r_new <= r {
                t.lost = true;
                continue;
            }
            t.at = at;
            t.frames += 1;
            add_sample(&mut t.sums, &p, at, travelled_m);
            t.depth = fit(&t.sums, travelled_m);
            // Keep the patch while it still matches well: every re-cut adds a little drift.
            if m.score < p.recut_score {
                let (cx, cy) = ((at[0] - 0.5).round() as usize, (at[1] - 0.5).round() as usize);
                if cx < half || cy < half || cx + half >= img.width || cy + half >= img.height {
                    t.lost = true;
                    continue;
                }
                t.patch.crop_from(img, Rect::new(cx - half, cy - half, cx + half + 1, cy + half + 1))?;
                t.patch_at = at;
            }
        }
        Ok(self.tracks().count())
    }
}

/// Unit direction from the FOE to `at`, and the distance.
fn radial(p: &DepthParams, at: [f32; 2]) -> ([f32; 2], f32) {
    let (dx, dy) = (at[0] - p.foe[0], at[1] - p.foe[1]);
    let r = dx.hypot(dy).max(1e-3);
    ([dx / r, dy / r], r)
}

fn cut(img: &Gray<'_>, x: usize, y: usize, half: usize) -> Result<GrayBuf, VisionError> {
    GrayBuf::crop(img, Rect::new(x - half, y - half, x + half + 1, y + half + 1))
}

/// Adds a sample `(T, 1/r)` weighted by `1 / var(1/r) = r⁴ / σ²`.
fn add_sample(s: &mut [f64; 5], p: &DepthParams, at: [f32; 2], travelled_m: f64) {
    let (_, r) = radial(p, at);
    let r = f64::from(r);
    let w = r.powi(4) / f64::from(p.noise_px).powi(2);
    let (t, y) = (travelled_m, 1.0 / r);
    for (k, v) in [w, w * t, w * t * t, w * y, w * t * y].into_iter().enumerate() {
        s[k] += v;
    }
}

/// Depth now and its standard deviation from the weighted line `1/r = a + b T`:
/// `Z0 = -a / b`, now `Z0 - T`, with the variance propagated from the fit's covariance.
fn fit(s: &[f64; 5], now: f64) -> Option<(f32, f32)> {
    let [sw, st, stt, sy, sty] = *s;
    let det = sw * stt - st * st;
    if det <= 0.0 {
        return None;
    }
    let b = (sw * sty - st * sy) / det;
    let a = (sy - b * st) / sw;
    if b >= 0.0 {
        return None;
    }
    // Covariance of (a, b): the inverse of [[Σw, ΣwT], [ΣwT, ΣwT²]].
    let (vaa, vbb, vab) = (stt / det, sw / det, -st / det);
    let z0 = -a / b;
    // dZ0/da = -1/b, dZ0/db = a/b².
    let (ga, gb) = (-1.0 / b, a / (b * b));
    let var = ga * ga * vaa + gb * gb * vbb + 2.0 * ga * gb * vab;
    Some(((z0 - now) as f32, var.max(0.0).sqrt() as f32))
}

/// Obstacle extraction: fits image row against `1/depth` over the tracked points below the
/// FOE (robustly: refits without the worst point while any lies off by more than the
/// tolerance), and returns, for each track, whether it stands off the ground line (`None`:
/// its depth is not yet known to better than `max_rel_sd`). The tolerance is `tol_px` plus
/// `tol_frac` of the point's height below the FOE in the image, as depth errors are relative.
pub fn obstacles(
    tracks: &[&Track],
    foe_v: f32,
    tol_px: f32,
    tol_frac: f32,
    max_rel_sd: f32,
) -> Vec<Option<bool>> {
    let tol = |v: f64| f64::from(tol_px) + f64::from(tol_frac) * (v - f64::from(foe_v)).max(0.0);
    let pts: Vec<(usize, f64, f64)> = tracks
        .iter()
        .enumerate()
        .filter_map(|(i, t)| {
            let known = t.depth.filter(|(z, sd)| *z > 0.0 && *sd <= max_rel_sd * *z);
            known.map(|(z, _)| (i, 1.0 / f64::from(z), f64::from(t.at[1])))
        })
        .collect();
    let mut ground: Vec<(usize, f64, f64)> = pts.iter().copied().filter(|p| p.2 > f64::from(foe_v)).collect();
    let mut line = (0.0, 0.0);
    while ground.len() >= 3 {
        let n = ground.len() as f64;
        let (sx, sy) = ground.iter().fold((0.0, 0.0), |a, p| (a.0 + p.1, a.1 + p.2));
        let (sxx, sxy) = ground.iter().fold((0.0, 0.0), |a, p| (a.0 + p.1 * p.1, a.1 + p.1 * p.2));
        let slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
        line = ((sy - slope * sx) / n, slope);
        let worst = ground
            .iter()
            .enumerate()
            .map(|(k, p)| (k, (p.2 - line.0 - line.1 * p.1).abs() / tol(line.0 + line.1 * p.1)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((k, e)) if e > 1.0 => {
                ground.swap_remove(k);
            }
            _ => break,
        }
    }
    let mut out = vec![None; tracks.len()];
    for (i, x, v) in pts {
        let ground_v = line.0 + line.1 * x;
        out[i] = Some(v < ground_v - tol(ground_v));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_radial_positions_give_the_exact_depth_and_a_shrinking_spread() {
        let p = DepthParams {
            foe: [320.0, 240.0],
            focal_px: 500.0,
            patch: 11,
            startup_reach_px: 30.0,
            update_reach_px: 3.0,
            noise_px: 0.5,
            min_score: 0.9,
            recut_score: 0.99,
            moravec: MoravecParams::default(),
        };
        // A point 12 m ahead, 0.8 m left and 0.5 m down of the axis.
        let (z0, lateral) = (12.0f64, [0.8f64, 0.5]);
        let mut sums = [0.0; 5];
        let mut spreads = Vec::new();
        for k in 0..6 {
            let t = 0.5 * k as f64;
            let at = [
                320.0 + (500.0 * lateral[0] / (z0 - t)) as f32,
                240.0 + (500.0 * lateral[1] / (z0 - t)) as f32,
            ];
            add_sample(&mut sums, &p, at, t);
            if let Some((z, sd)) = fit(&sums, t) {
                assert!((f64::from(z) - (z0 - t)).abs() < 1e-3 * z0, "frame {k}: {z} vs {}", z0 - t);
                spreads.push(sd);
            }
        }
        assert_eq!(spreads.len(), 5);
        assert!(spreads.windows(2).all(|w| w[1] < w[0]), "{spreads:?}");
        // A point that does not move away from the FOE has no depth.
        let mut still = [0.0; 5];
        add_sample(&mut still, &p, [400.0, 300.0], 0.0);
        add_sample(&mut still, &p, [400.0, 300.0], 0.5);
        assert_eq!(fit(&still, 0.5), None);
    }
}
