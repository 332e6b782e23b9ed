//! The odometry's features stop to stop: each carried one looked for again where the predicted
//! motion puts it and ranged, and new ones taken from the stop's pair where the carried ones are
//! not (003: reacquisition on the time axis, interest operator and stereo on the stereo axis).

use super::{Feature, OdometryError, Pair, Prior, VisualOdometry, magnify, reacquire, select};
use crate::image::{Gray, GrayBuf, Rect};
use crate::nc::Template;

impl VisualOdometry {
    /// Each carried feature looked for in its predicted box and ranged: `self.pairs` and, in
    /// the same order, `self.found` (the features as seen at this stop).
    pub(super) fn reacquire(
        &mut self,
        left: &Gray<'_>,
        right: &Gray<'_>,
        prior: &Prior,
    ) -> Result<(), OdometryError> {
        let p = &self.params;
        let half = p.stereo.patch / 2;
        self.pairs.clear();
        self.found.clear();
        for f in &self.features {
            let size = [left.width, left.height];
            let Some(window) = reacquire::predicted_box(&p.rig, f.point, prior, p.box_sigmas, size, half)
            else {
                continue;
            };
            match &mut self.template {
                Some(t) => t.set(&f.patch)?,
                None => self.template = Some(Template::new(&f.patch)?),
            }
            let Some(template) = &self.template else { continue };
            let m = self.correlator.best(left, window, template)?;
            if m.score < p.track_min_score {
                continue;
            }
            // The match lies off the feature by the view's magnification of its patch.
            let a = magnify::local_affine(&p.rig, f.at, f.point, &prior.motion);
            let d = magnify::drift(&f.patch, a);
            let at = [m.centre[0] - d[0] as f32, m.centre[1] - d[1] as f32];
            if !(at[0] >= 0.0 && at[1] >= 0.0) {
                continue;
            }
            let (x, y) = (at[0] as usize, at[1] as usize);
            if x < half || y < half || x + half >= left.width || y + half >= left.height {
                continue;
            }
            let Some(s) = self.stereo.match_at(left, right, x, y, &p.stereo)? else { continue };
            let Some(point) = p.rig.triangulate(at, s.disparity) else { continue };
            self.pairs.push(Pair {
                old: f.point,
                new: point,
                old_cov: p.rig.covariance(f.point),
                new_cov: p.rig.covariance(point),
            });
            self.found.push(Feature { point, at, patch: patch_at(left, x, y, half)? });
        }
        Ok(())
    }

    /// New features ranged in the left image, away from those carried, up to the interest
    /// operator's count in all.
    pub(super) fn top_up(&mut self, left: &Gray<'_>, right: &Gray<'_>) -> Result<(), OdometryError> {
        let p = &self.params;
        let half = p.stereo.patch / 2;
        let spacing = p.spacing_px * p.spacing_px;
        let noise =
            if p.min_turn > 0.0 { f64::from(crate::noise::noise_sigma(left, left.full())) } else { 0.0 };
        let matches = self.stereo.match_points(left, right, left.full(), &p.stereo)?;
        for m in matches {
            if self.features.len() >= p.stereo.moravec.max_corners {
                break;
            }
            let near = |f: &Feature| (f.at[0] - m.left[0]).powi(2) + (f.at[1] - m.left[1]).powi(2) < spacing;
            if self.features.iter().any(near) {
                continue;
            }
            let (x, y) = (m.left[0] as usize, m.left[1] as usize);
            if p.min_turn > 0.0 && select::turn_ratio(left, x, y, half, noise).is_none_or(|t| t < p.min_turn)
            {
                continue;
            }
            let Some(point) = p.rig.triangulate(m.left, m.disparity) else { continue };
            self.features.push(Feature { point, at: m.left, patch: patch_at(left, x, y, half)? });
        }
        Ok(())
    }
}

/// The `(2 half + 1)²` patch of `img` centred on pixel `(x, y)`.
fn patch_at(img: &Gray<'_>, x: usize, y: usize, half: usize) -> Result<GrayBuf, OdometryError> {
    Ok(GrayBuf::crop(img, Rect::new(x - half, y - half, x + half + 1, y + half + 1))?)
}
