//! The path's edges found by their steps when the line finder's fragments fall short (001 §2.1's
//! path following on a dim, noisy day: gravel against dry grass steps a few noise deviations, and
//! the fragments the line finder keeps are too few to group): near each predicted edge, the
//! straight line along which the step across it, summed down the columns, stands out most
//! (`step_line.rs`), lighter or darker going down, whichever stands out more.

use crate::path::{ImageLine, PathFit, PathTracker};
use crate::step_line::{MAX_ANGLE, Profiles, StepLine};
use crate::{Gray, Rect};

/// A line counts when its summed step is this many times what noise and texture summed over as
/// many columns would reach (noise alone over a window's lines reaches 6-7).
const MIN_Z: f32 = 8.0;
/// Of the columns a line crosses, at least this share must step by a spread (see `support`) near
/// it: a checker's diagonal on a gravel path sums to a line too, from some of its columns.
const MIN_SUPPORT: f32 = 0.6;
const SUPPORT_BAND_ROWS: f32 = 1.5;
/// The least spread a column's step is taken to have (grey levels): a noiseless, flat frame's is
/// none, and any step would stand out of it.
const MIN_SPREAD: f32 = 1.0;
/// Lines tried, best first, for one near the prediction.
const LINES_TRIED: usize = 3;
/// Every second column is profiled.
const COLUMN_STEP: usize = 2;

/// Reusable buffers of the search.
#[derive(Debug, Default)]
pub struct StepSearch {
    profiles: Profiles,
    scratch: Vec<(f32, u32)>,
    spread: Vec<f32>,
}

/// `a` as a direction within a half turn of the rows: (-pi/2, pi/2].
fn half_turn(a: f32) -> f32 {
    use std::f32::consts::PI;
    let a = a.rem_euclid(PI);
    if a > PI / 2.0 { a - PI } else { a }
}

impl StepSearch {
    /// The edge near `predicted` in `window` of `img`, between rows `rows` (the horizon, the
    /// bottom): within `reach` px of it at the bottom row and `max_angle` of its direction.
    /// With its length in the columns it crosses (px).
    fn edge(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        predicted: &ImageLine,
        rows: (f32, f32),
        (reach, max_angle): (f32, f32),
    ) -> Option<(ImageLine, f32)> {
        let bottom = rows.1;
        let rect = around(window, predicted, rows, reach)?;
        let a = half_turn(predicted.angle);
        let mut best: Option<(f32, StepLine)> = None;
        for darker in [false, true] {
            self.profiles.measure(img, rect, COLUMN_STEP, darker);
            let sd = self.profiles.spread(&mut self.spread).max(MIN_SPREAD);
            // A stronger line of like direction beyond reach (the box spans the whole edge) is
            // set aside for the next.
            for _ in 0..LINES_TRIED {
                let Some(l) = self.profiles.best_line((a - max_angle, a + max_angle), &mut self.scratch)
                else {
                    break;
                };
                let z = l.z(sd);
                if z < MIN_Z {
                    break;
                }
                let near = (l.line.x_at(bottom) - predicted.x_at(bottom)).abs() <= reach;
                if !near {
                    self.profiles.suppress(&l.line, SUPPORT_BAND_ROWS);
                    continue;
                }
                if best.is_none_or(|b| z > b.0)
                    && self.profiles.support(&l.line, SUPPORT_BAND_ROWS, sd) >= MIN_SUPPORT
                {
                    best = Some((z, l));
                }
                break;
            }
        }
        best.map(|(_, l)| (l.line, l.columns as f32 * COLUMN_STEP as f32 / l.line.angle.cos().abs()))
    }

    /// Whether `line` is an edge (lighter or darker going down) by its steps: its summed step
    /// standing out as a found line's must, and the share of the columns it crosses between
    /// `rows` that step near it at least `MIN_SUPPORT`. A line steeper than the columns can
    /// measure (an edge close beside the robot) is taken as it is.
    fn supports(&mut self, img: &Gray<'_>, window: Rect, line: &ImageLine, rows: (f32, f32)) -> bool {
        if half_turn(line.angle).abs() > MAX_ANGLE {
            return true;
        }
        let Some(rect) = around(window, line, rows, 0.0) else { return false };
        [false, true].into_iter().any(|darker| {
            self.profiles.measure(img, rect, COLUMN_STEP, darker);
            let sd = self.profiles.spread(&mut self.spread).max(MIN_SPREAD);
            let (sum, columns) = self.profiles.sum_along(line, 1);
            let z = StepLine { line: *line, sum, columns }.z(sd);
            z >= MIN_Z && self.profiles.support(line, SUPPORT_BAND_ROWS, sd) >= MIN_SUPPORT
        })
    }
}

/// The part of `window` between `rows` (the horizon, the bottom) where `line` runs, `reach` px
/// either side; none when that is empty.
fn around(window: Rect, line: &ImageLine, (top, bottom): (f32, f32), reach: f32) -> Option<Rect> {
    let xs = [line.x_at(top + 1.0), line.x_at(bottom)];
    let lo = (xs[0].min(xs[1]) - reach).max(window.x0 as f32);
    let hi = (xs[0].max(xs[1]) + reach).min(window.x1 as f32);
    let y0 = (top.ceil().max(0.0) as usize).max(window.y0);
    (lo < hi && y0 < window.y1).then(|| Rect::new(lo as usize, y0, hi.ceil() as usize, window.y1))
}

impl PathTracker {
    /// Update with a frame: by its line fragments (`update`) where both edges of the fit are
    /// edges by their steps too (on a gravel path in a dim, noisy light the fragments group into
    /// a checker's diagonals as readily as into the edges), else by the edges' steps alone
    /// (`update_by_steps`). `None`: lost.
    pub fn update_checked(
        &mut self,
        lines: &[crate::flf::Line],
        img: &Gray<'_>,
        window: Rect,
        search: &mut StepSearch,
    ) -> Option<PathFit> {
        let before = self.clone();
        let rows = (self.horizon_v, self.bottom_v);
        if let Some(fit) = self.update(lines) {
            if search.supports(img, window, &fit.left, rows) && search.supports(img, window, &fit.right, rows)
            {
                return Some(fit);
            }
            *self = before;
        }
        self.update_by_steps(img, window, search)
    }

    /// Update with a frame itself when its line fragments gave no confident fit: each edge found
    /// by its step near the prediction (within the tracker's tolerances, not widened: a faint
    /// edge's search reaches further than its fragments' grouping), the
    /// length of the columns each crosses the confidence. A fit whose edges cross below the
    /// middle of the rows the path was last seen on, or that does not follow from the prediction
    /// (`PathTracker::follows`), is refused, as `update` refuses one. A
    /// confident fit becomes the next prediction; `None`: lost.
    pub fn update_by_steps(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        search: &mut StepSearch,
    ) -> Option<PathFit> {
        let p = self.params;
        let rows = (self.horizon_v, self.bottom_v);
        let tolerance = (p.max_distance_px, p.max_angle);
        let (l, wl) = search.edge(img, window, &self.left, rows, tolerance)?;
        let (r, wr) = search.edge(img, window, &self.right, rows, tolerance)?;
        let vanishing = l.cross(&r)?;
        let bottom = [(l.x_at(self.bottom_v) + r.x_at(self.bottom_v)) / 2.0, self.bottom_v];
        let fit = PathFit {
            left: l,
            right: r,
            centreline: ImageLine::through(vanishing, bottom),
            vanishing,
            confidence: wl + wr,
        };
        if !self.takes(&fit, &p) {
            return None;
        }
        (self.left, self.right, self.horizon_v) = (fit.left, fit.right, fit.vanishing[1]);
        Some(fit)
    }
}
