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

pub use crate::depth_ground::{obstacles, standing_off_floor};
pub use crate::register::register;

use crate::depth_fit::{add_sample, fit};
use crate::depth_radial::{RADIAL_CANDIDATES, radially_distinct};

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthParams {
    /// Focus of expansion (pixels) and focal length (pixels).
    pub foe: [f32; 2],
    pub focal_px: f32,
    /// Side of the patch tracked by correlation (odd).
    pub patch: usize,
    /// Start-up search: how far out along the radial line a point may move (pixels), and the
    /// nearest depth it may have (m; 0: any): the search reaches no further out than a point
    /// that near would move, so a look-alike further along the line is not taken for it.
    pub startup_reach_px: f32,
    pub min_depth_m: f64,
    /// Update search: the window round the predicted position (pixels each way).
    pub update_reach_px: f32,
    /// Measurement noise of a matched position (pixels), weighting the fit.
    pub noise_px: f32,
    /// Least correlation score of a kept match.
    pub min_score: f32,
    /// Below this score the patch is cut afresh from the current frame.
    pub recut_score: f32,
    /// How far the frame's shift may be from the guess (pixels; 0: the guess is taken as it is).
    pub register_reach_px: f32,
    pub moravec: MoravecParams,
}

/// One tracked point.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// Its number at start-up.
    pub id: usize,
    /// Image position now, in the start-up frame's coordinates (a registered frame shifted back).
    pub at: [f32; 2],
    /// Depth now along the optical axis (m) and its standard deviation; `None` before two frames.
    pub depth: Option<(f32, f32)>,
    /// Frames it has been matched in.
    pub frames: usize,
    /// Sums of the weighted fit of `1/r` against travel: Σw, ΣwT, ΣwT², Σw/r, ΣwT/r, Σw/r²,
    /// and the samples' count.
    sums: [f64; 7],
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
    shift: [f32; 2],
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
            shift: [0.0, 0.0],
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
        self.shift = [0.0, 0.0];
        // More candidates than points: those on an edge running out from the FOE are dropped.
        let wanted = p.moravec.max_corners;
        let candidates = MoravecParams { max_corners: wanted.saturating_mul(RADIAL_CANDIDATES), ..p.moravec };
        for c in self.moravec.corners(img, window, &candidates)? {
            let (x, y) = (c.x, c.y);
            if self.tracks.len() >= wanted {
                break;
            }
            if x < half || y < half || x + half >= img.width || y + half >= img.height {
                continue;
            }
            let at = [x as f32 + 0.5, y as f32 + 0.5];
            if !radially_distinct(img, &p, at)? {
                continue;
            }
            let id = self.tracks.len();
            let patch = GrayBuf::default();
            let mut t =
                Track { id, at, depth: None, frames: 1, sums: [0.0; 7], patch, patch_at: at, lost: false };
            add_sample(&mut t.sums, &p, at, travelled_m);
            t.patch = cut(img, x, y, half)?;
            self.tracks.push(t);
        }
        Ok(self.tracks.len())
    }

    /// Update: the next frame, taken at travel `travelled_m` (metres along the axis since any
    /// fixed origin). Returns how many points are still tracked.
    pub fn update(&mut self, img: &Gray<'_>, travelled_m: f64) -> Result<usize, VisionError> {
        self.update_registered(img, travelled_m, [0.0, 0.0])
    }

    /// [`Self::update`] on a frame shifted by about `guess_px` against the start-up frame (the
    /// registration 001 §2.3 asks for: a camera that turned a little since start-up sees the
    /// scene moved sideways by about `f` times the angle). With `register_reach_px` set, the
    /// shift is measured within that reach of the guess: each point is matched in a window
    /// widened by it, and the shift is the one that puts the matches back on their radial lines
    /// ([`register`]). Points are kept, and their depths fitted, in the start-up frame's
    /// coordinates; the search and the patches are in this one.
    pub fn update_registered(
        &mut self,
        img: &Gray<'_>,
        travelled_m: f64,
        guess_px: [f32; 2],
    ) -> Result<usize, VisionError> {
        let p = self.params;
        if !guess_px.iter().all(|s| s.is_finite()) {
            return Err(VisionError::BadParameter(format!("registration shift {guess_px:?}")));
        }
        let step = travelled_m - self.travelled_m;
        if step.is_nan() || step <= 0.0 {
            return Err(VisionError::BadParameter(format!(
                "travel must grow: {} after {}",
                travelled_m, self.travelled_m
            )));
        }
        self.travelled_m = travelled_m;
        let half = p.patch / 2;
        let reach = p.update_reach_px.max(2.0) + p.register_reach_px;
        // Each live point's best match in this frame's coordinates.
        let mut matched = Vec::with_capacity(self.tracks.len());
        for t in self.tracks.iter_mut().filter(|t| !t.lost) {
            let (lo, hi) = expected_radii(&p, t, step);
            let (d, _) = radial(&p, t.at);
            let pt = |rr: f32| [p.foe[0] + d[0] * rr + guess_px[0], p.foe[1] + d[1] * rr + guess_px[1]];
            let (a, b) = (pt(lo.max(0.0)), pt(hi));
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
            if m.score < p.min_score {
                t.lost = true;
                continue;
            }
            // The patch was cut centred on the pixel holding the point: keep its offset.
            let pa = t.patch_at;
            let off = [pa[0] - (pa[0] - 0.5).round() - 0.5, pa[1] - (pa[1] - 0.5).round() - 0.5];
            matched.push((t.id, [m.centre[0] + off[0], m.centre[1] + off[1]], m.score));
        }
        let shift = if p.register_reach_px > 0.0 {
            let lines: Vec<([f32; 2], [f32; 2])> = matched
                .iter()
                .map(|&(id, at, _)| (radial(&p, self.tracks[id].at).0, [at[0] - p.foe[0], at[1] - p.foe[1]]))
                .collect();
            register(&lines, guess_px, p.register_reach_px)
        } else {
            guess_px
        };
        self.shift = shift;
        for (id, here, score) in matched {
            let Some(t) = self.tracks.get_mut(id) else { continue };
            let at = [here[0] - shift[0], here[1] - shift[1]];
            // A static point stays on its radial line, moving out as far as its depth says.
            let (d, r) = radial(&p, t.at);
            let (lo, hi) = expected_radii(&p, t, step);
            let (_, r_new) = radial(&p, at);
            let across = (at[0] - p.foe[0]) * d[1] - (at[1] - p.foe[1]) * d[0];
            let slack = p.update_reach_px.max(2.0);
            if across.abs() > 1.5 || r_new <= r || r_new < lo - slack || r_new > hi + slack {
                t.lost = true;
                continue;
            }
            t.at = at;
            t.frames += 1;
            add_sample(&mut t.sums, &p, at, travelled_m);
            t.depth = fit(&t.sums, travelled_m);
            // Keep the patch while it still matches well: every re-cut adds a little drift.
            if score < p.recut_score {
                let (cx, cy) = ((here[0] - 0.5).round(), (here[1] - 0.5).round());
                let fits = |c: f32, n: usize| c >= half as f32 && c + (half as f32) < n as f32;
                if !fits(cx, img.width) || !fits(cy, img.height) {
                    t.lost = true;
                    continue;
                }
                let (cx, cy) = (cx as usize, cy as usize);
                t.patch.crop_from(img, Rect::new(cx - half, cy - half, cx + half + 1, cy + half + 1))?;
                t.patch_at = here;
            }
        }
        Ok(self.tracks().count())
    }

    /// The shift the last update registered its frame by (px).
    pub fn shift(&self) -> [f32; 2] {
        self.shift
    }
}

/// How far from the FOE `t` may be after a further `step` of travel: round where its depth puts
/// it, or anywhere out along its ray before it has a depth.
fn expected_radii(p: &DepthParams, t: &Track, step: f64) -> (f32, f32) {
    let (_, r) = radial(p, t.at);
    match t.depth {
        Some((z, _)) if f64::from(z) > step => {
            let r_next = r * z / (z - step as f32);
            (r_next - p.update_reach_px, r_next + p.update_reach_px)
        }
        // Nothing nearer than `min_depth_m` moves further out than that depth allows.
        _ if p.min_depth_m > step => {
            let near = (f64::from(r) * step / (p.min_depth_m - step)) as f32;
            (r, r + near.min(p.startup_reach_px))
        }
        _ => (r, r + p.startup_reach_px),
    }
}

/// Unit direction from the FOE to `at`, and the distance.
pub(crate) fn radial(p: &DepthParams, at: [f32; 2]) -> ([f32; 2], f32) {
    let (dx, dy) = (at[0] - p.foe[0], at[1] - p.foe[1]);
    let r = dx.hypot(dy).max(1e-3);
    ([dx / r, dy / r], r)
}

fn cut(img: &Gray<'_>, x: usize, y: usize, half: usize) -> Result<GrayBuf, VisionError> {
    GrayBuf::crop(img, Rect::new(x - half, y - half, x + half + 1, y + half + 1))
}
