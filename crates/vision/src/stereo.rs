//! Two-camera stereo (003): interesting points of the left image are matched by correlation in
//! the right image along their epipolar line (the same row for parallel cameras), widened to a
//! band of rows for calibration error, and only over the disparities the near and far limits
//! allow; depth is `f b / disparity`. A match must be unique: no placement more than two pixels
//! off may score nearly as well (`min_margin`).

use crate::GrayBuf;
use crate::image::{Gray, Rect, VisionError};
use crate::moravec::{Corner, Moravec, MoravecParams};
use crate::nc::{Correlator, Template};

/// The rig and the search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoParams {
    pub focal_px: f32,
    /// Distance between the cameras (m); the right camera is to the right of the left one.
    pub baseline_m: f32,
    /// Rows above and below the epipolar line to search.
    pub band_rows: usize,
    /// Depths outside `near_m ..= far_m` are not looked for.
    pub near_m: f32,
    pub far_m: f32,
    /// Side of the correlated patch (odd).
    pub patch: usize,
    pub min_score: f32,
    /// The best score must beat the best one more than two pixels away by this much (0: not
    /// asked), or the point is not matched: it lies on an edge or a repeated pattern.
    pub min_margin: f32,
    pub moravec: MoravecParams,
}

/// One matched point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoMatch {
    /// Its position in the left image (pixel centre).
    pub left: [f32; 2],
    /// Horizontal disparity (pixels, sub-pixel) and vertical offset found within the band.
    pub disparity: f32,
    pub row_offset: f32,
    pub depth_m: f32,
    pub score: f32,
}

/// The matcher with its buffers.
#[derive(Debug, Default)]
pub struct Stereo {
    moravec: Moravec,
    correlator: Correlator,
    patch: GrayBuf,
    template: Option<Template>,
    matches: Vec<StereoMatch>,
}

impl Stereo {
    /// Matches the interesting points of `window` (left image) in the right image.
    pub fn match_points(
        &mut self,
        left: &Gray<'_>,
        right: &Gray<'_>,
        window: Rect,
        p: &StereoParams,
    ) -> Result<&[StereoMatch], VisionError> {
        check(left, right, p)?;
        self.matches.clear();
        self.moravec.corners(left, window, &p.moravec)?;
        for i in 0..self.moravec.last_corners().len() {
            let Corner { x, y, .. } = self.moravec.last_corners()[i];
            if let Some(m) = self.search(left, right, x, y, p)? {
                self.matches.push(m);
            }
        }
        Ok(&self.matches)
    }

    /// Matches the patch centred on pixel `(x, y)` of the left image in the right image, along
    /// its band and within the near and far limits: `None` when it lies too near an edge, no
    /// disparity is allowed there or the best correlation is below `min_score`.
    pub fn match_at(
        &mut self,
        left: &Gray<'_>,
        right: &Gray<'_>,
        x: usize,
        y: usize,
        p: &StereoParams,
    ) -> Result<Option<StereoMatch>, VisionError> {
        check(left, right, p)?;
        self.search(left, right, x, y, p)
    }

    /// [`Stereo::match_at`] once the images and settings are checked.
    fn search(
        &mut self,
        left: &Gray<'_>,
        right: &Gray<'_>,
        x: usize,
        y: usize,
        p: &StereoParams,
    ) -> Result<Option<StereoMatch>, VisionError> {
        let fb = p.focal_px * p.baseline_m;
        let (d_min, d_max) = (fb / p.far_m, fb / p.near_m);
        let half = p.patch / 2;
        if x < half
            || y < half + p.band_rows
            || y + half + p.band_rows >= left.height
            || x + half >= left.width
        {
            return Ok(None);
        }
        // In the right image the point lies `d` to the left: x - d for d in the allowed range.
        let lo = x as f32 - d_max;
        let hi = x as f32 - d_min;
        if hi < half as f32 {
            return Ok(None);
        }
        let x0 = lo.max(half as f32).floor() as usize - half;
        let x1 = (hi.ceil() as usize + half + 1).min(right.width);
        let win = Rect::new(x0, y - half - p.band_rows, x1, y + half + p.band_rows + 1);
        if win.width() < p.patch {
            return Ok(None);
        }
        self.patch.crop_from(left, Rect::new(x - half, y - half, x + half + 1, y + half + 1))?;
        match &mut self.template {
            Some(t) => t.set(&self.patch)?,
            None => self.template = Some(Template::new(&self.patch)?),
        }
        let Some(t) = &self.template else { return Ok(None) };
        let m = self.correlator.best(right, win, t)?;
        let (left_c, right_c) = ([x as f32 + 0.5, y as f32 + 0.5], m.centre);
        let disparity = left_c[0] - right_c[0];
        if m.score < p.min_score || !(d_min..=d_max).contains(&disparity) {
            return Ok(None);
        }
        if p.min_margin > 0.0
            && m.score - crate::unique::runner_up(&mut self.correlator, right, win, t, &m, 2)? < p.min_margin
        {
            return Ok(None);
        }
        Ok(Some(StereoMatch {
            left: left_c,
            disparity,
            row_offset: right_c[1] - left_c[1],
            depth_m: fb / disparity,
            score: m.score,
        }))
    }
}

/// The pair must be the same size and the settings sensible.
fn check(left: &Gray<'_>, right: &Gray<'_>, p: &StereoParams) -> Result<(), VisionError> {
    if (left.width, left.height) != (right.width, right.height) {
        return Err(VisionError::BadParameter("left and right images differ in size".into()));
    }
    if p.patch.is_multiple_of(2)
        || p.patch < 3
        || !(p.near_m > 0.0 && p.far_m > p.near_m && p.baseline_m > 0.0)
    {
        return Err(VisionError::BadParameter(format!("stereo settings {p:?}")));
    }
    Ok(())
}
