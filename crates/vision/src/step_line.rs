//! A straight step edge found by integrating along it: down every column of a window the step
//! across each row (the mean of three rows below less that of three above, signed so the wanted
//! step is positive), then, over candidate lines, the steps summed along each line across the
//! columns. A faint edge that no single column shows above its noise (gravel against grass on a
//! dim, noisy day: some 2-3 of the step's own deviations) stands out summed over a hundred
//! columns, while noise and texture that do not line up cancel. The best line is judged by its
//! sum against the noise a sum of as many columns would have; each column's own edge is then
//! looked for near it (`peak_near`).

use crate::path::ImageLine;
use crate::{Gray, Rect};

/// Rows either side of a row its step is measured over.
pub const HALF_ROWS: usize = 3;
/// Lines steeper than this (radians from the image's rows) cross too few rows of a column's
/// profile to be found by them.
pub const MAX_ANGLE: f32 = 1.3;
/// The coarse search: every second profile column, angles a shift of this many rows at the
/// window's edge apart, then refined round the best at a quarter of that and every row.
const COARSE_ROWS: f32 = 2.0;
const REFINE_STEPS: i32 = 4;
const REFINE_ROWS: i32 = 3;
/// A line must cross at least this many profile columns to be scored.
const MIN_COLUMNS: usize = 8;

/// The column step profiles of a window.
#[derive(Debug, Default, Clone)]
pub struct Profiles {
    /// The image columns profiled, left to right.
    pub columns: Vec<usize>,
    /// The first row with a profile value (the window's top plus `HALF_ROWS`) and how many.
    pub top: usize,
    pub rows: usize,
    /// Column-major: `data[c * rows + (v - top)]`.
    data: Vec<f32>,
}

/// A line through the window and its summed step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepLine {
    pub line: ImageLine,
    /// The steps summed along it (grey levels), over `columns` profile columns.
    pub sum: f32,
    pub columns: usize,
}

impl StepLine {
    /// The sum in units of the deviation a sum of as many columns of noise alone would have, each
    /// column's step having deviation `step_sd`.
    pub fn z(&self, step_sd: f32) -> f32 {
        self.sum / (step_sd.max(1e-3) * (self.columns as f32).sqrt())
    }
}

impl Profiles {
    /// Profiles every `column_step`th column of `win` (inside `img`), wanted steps positive:
    /// going darker down the column when `darker`, lighter otherwise. Empty when the window has
    /// too few rows.
    pub fn measure(&mut self, img: &Gray<'_>, win: Rect, column_step: usize, darker: bool) {
        self.columns.clear();
        self.data.clear();
        let (y0, y1) = (win.y0 + HALF_ROWS, win.y1.min(img.height).saturating_sub(HALF_ROWS));
        (self.top, self.rows) = (y0, y1.saturating_sub(y0));
        if self.rows == 0 {
            return;
        }
        let sign = if darker { -1.0 / HALF_ROWS as f32 } else { 1.0 / HALF_ROWS as f32 };
        for u in (win.x0..win.x1.min(img.width)).step_by(column_step.max(1)) {
            self.columns.push(u);
            let at = |v: usize| f32::from(img.at(u, v));
            // A running sum of the three rows below less the three above.
            let mut below: f32 = (1..=HALF_ROWS).map(|k| at(y0 + k)).sum();
            let mut above: f32 = (1..=HALF_ROWS).map(|k| at(y0 - k)).sum();
            for v in y0..y1 {
                if v > y0 {
                    below += at(v + HALF_ROWS) - at(v);
                    above += at(v - 1) - at(v - 1 - HALF_ROWS);
                }
                self.data.push(sign * (below - above));
            }
        }
    }

    /// The step at profile column `c`, image row `v` (none outside the profiled rows).
    pub fn at(&self, c: usize, v: usize) -> Option<f32> {
        let r = v.checked_sub(self.top).filter(|&r| r < self.rows)?;
        self.data.get(c * self.rows + r).copied()
    }

    /// The best line with its direction within `angles` (radians, each within `MAX_ANGLE` of
    /// the rows): the greatest summed step in units of its columns' noise (the sum over the
    /// square root of the columns it crosses). None when no line crosses enough columns.
    pub fn best_line(&self, angles: (f32, f32), scratch: &mut Vec<(f32, u32)>) -> Option<StepLine> {
        let (lo, hi) = (angles.0.max(-MAX_ANGLE), angles.1.min(MAX_ANGLE));
        if self.columns.len() < MIN_COLUMNS || self.rows == 0 || lo > hi {
            return None;
        }
        let (first, last) = (self.columns[0] as f32, self.columns[self.columns.len() - 1] as f32);
        let (mid, half) = ((first + last) / 2.0, ((last - first) / 2.0).max(1.0));
        // Angles a given shift at the window's edge apart: finer where the lines are steep.
        let step_at = |a: f32, rows: f32| rows / half * a.cos().powi(2);
        let mut best: Option<(f32, f32, f32)> = None;
        let mut a = lo;
        while a <= hi {
            if let Some((z, v)) = self.best_offset(a.tan(), mid, 2, None, scratch)
                && best.is_none_or(|b| z > b.0)
            {
                best = Some((z, a, v));
            }
            a += step_at(a, COARSE_ROWS).max(1e-4);
        }
        let (_, a0, v0) = best?;
        let fine = step_at(a0, COARSE_ROWS) / REFINE_STEPS as f32;
        let mut refined: Option<(f32, f32, f32)> = None;
        for k in -REFINE_STEPS..=REFINE_STEPS {
            let a = (a0 + k as f32 * fine).clamp(lo, hi);
            let near = (v0 - REFINE_ROWS as f32, v0 + REFINE_ROWS as f32);
            if let Some((z, v)) = self.best_offset(a.tan(), mid, 1, Some(near), scratch)
                && refined.is_none_or(|b| z > b.0)
            {
                refined = Some((z, a, v));
            }
        }
        let (_, a, v) = refined?;
        // In image coordinates: a profile column's pixel centre, and the edge half a row below
        // the profile row its sum peaks at (a sharp edge at image y = k, between rows k - 1 and
        // k, steps fully at both, so the peak row is k - 1 or k: the line within half a row).
        let line = ImageLine { point: [mid + 0.5, v + 0.5], angle: a };
        let (sum, columns) = self.sum_along(&line, 1);
        Some(StepLine { line, sum, columns })
    }

    /// For lines of slope `b` through (`mid`, v), the v (whole rows, within `near` if given)
    /// whose sum over every `every`th profile column, in units of the square root of the columns
    /// crossed, is greatest; with that figure.
    fn best_offset(
        &self,
        b: f32,
        mid: f32,
        every: usize,
        near: Option<(f32, f32)>,
        acc: &mut Vec<(f32, u32)>,
    ) -> Option<(f32, f32)> {
        // Offsets: lines through row `top + i - pad` at `mid`.
        let pad = (b.abs()
            * (mid - self.columns[0] as f32).abs().max(self.columns[self.columns.len() - 1] as f32 - mid))
        .ceil() as usize
            + 1;
        let span = self.rows + 2 * pad;
        acc.clear();
        acc.resize(span, (0.0, 0));
        for (c, &u) in self.columns.iter().enumerate().step_by(every) {
            let shift = (b * (u as f32 - mid)).round() as isize;
            // Offset i meets this column at profile row i - pad + shift.
            let col = &self.data[c * self.rows..(c + 1) * self.rows];
            let start = (pad as isize - shift).max(0) as usize;
            let end = ((self.rows + pad) as isize - shift).clamp(0, span as isize) as usize;
            for (i, slot) in acc.iter_mut().enumerate().take(end).skip(start) {
                let r = (i as isize - pad as isize + shift) as usize;
                slot.0 += col[r];
                slot.1 += 1;
            }
        }
        let min = (MIN_COLUMNS / every).max(2) as u32;
        let in_range = |i: usize| {
            let v = (self.top + i) as f32 - pad as f32;
            near.is_none_or(|(a, z)| v >= a && v <= z)
        };
        acc.iter()
            .enumerate()
            .filter(|&(i, &(_, n))| n >= min && in_range(i))
            .map(|(i, &(s, n))| (s / (n as f32).sqrt(), (self.top + i) as f32 - pad as f32))
            .max_by(|p, q| p.0.total_cmp(&q.0))
    }

    /// The profile row (fractional) where `line` (image coordinates) crosses profile column `c`.
    fn row_on(&self, line: &ImageLine, c: usize) -> Option<f32> {
        Some(line.y_at(*self.columns.get(c)? as f32 + 0.5) - 0.5)
    }

    /// The steps summed along `line` (image coordinates; each profile column at its nearest
    /// row) over every `every`th column, and how many columns it crossed.
    pub fn sum_along(&self, line: &ImageLine, every: usize) -> (f32, usize) {
        let mut out = (0.0, 0);
        for c in (0..self.columns.len()).step_by(every.max(1)) {
            let v = self.row_on(line, c).unwrap_or(-1.0).round();
            if v >= 0.0
                && let Some(s) = self.at(c, v as usize)
            {
                out = (out.0 + s, out.1 + 1);
            }
        }
        out
    }

    /// The share of the profile columns `line` crosses whose own step within `band` rows of it is
    /// at least `least`: an edge steps in nearly every column, while a line of texture (a
    /// checker's diagonal) sums its steps from some columns only.
    pub fn support(&self, line: &ImageLine, band: f32, least: f32) -> f32 {
        let (mut crossed, mut stepped) = (0u32, 0u32);
        for c in 0..self.columns.len() {
            let v = self.row_on(line, c).unwrap_or(-1.0).round();
            if v >= 0.0 && self.at(c, v as usize).is_some() {
                crossed += 1;
                stepped += u32::from(self.peak_near(c, line, band, least).is_some());
            }
        }
        if crossed == 0 { 0.0 } else { stepped as f32 / crossed as f32 }
    }

    /// Zeroes the steps within `band` rows of `line` (image coordinates), so that the next
    /// search finds the next best line.
    pub fn suppress(&mut self, line: &ImageLine, band: f32) {
        for c in 0..self.columns.len() {
            let Some(v) = self.row_on(line, c) else { continue };
            let (lo, hi) = ((v - band).floor().max(0.0) as usize, (v + band).ceil().max(0.0) as usize);
            for r in lo.max(self.top)..=hi.min((self.top + self.rows).saturating_sub(1)) {
                self.data[c * self.rows + r - self.top] = 0.0;
            }
        }
    }

    /// The spread of a column's step where there is no edge, robustly: 1.4826 times the median
    /// of the profiles' absolute values (noise and texture alike; an edge fills few rows of a
    /// column). `scratch` is reused.
    pub fn spread(&self, scratch: &mut Vec<f32>) -> f32 {
        scratch.clear();
        scratch.extend(self.data.iter().map(|x| x.abs()));
        if scratch.is_empty() {
            return 0.0;
        }
        let mid = scratch.len() / 2;
        let (_, m, _) = scratch.select_nth_unstable_by(mid, f32::total_cmp);
        1.4826 * *m
    }

    /// Column `c`'s edge within `band` rows of where `line` (image coordinates) crosses it: the
    /// row of its greatest step if that is at least `least`, placed (as an image coordinate: a
    /// sharp edge between rows k - 1 and k at k) by the steps near the peak of at least half of
    /// it, weighted.
    pub fn peak_near(&self, c: usize, line: &ImageLine, band: f32, least: f32) -> Option<f64> {
        let v = self.row_on(line, c)?;
        let rows = |a: f32, z: f32| {
            let a = (a.floor().max(self.top as f32)) as usize;
            let z = (z.ceil().max(0.0) as usize).min(self.top + self.rows);
            a..z
        };
        let (r, peak) = rows(v - band, v + band + 1.0)
            .filter_map(|r| Some((r, self.at(c, r)?)))
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        if peak < least {
            return None;
        }
        let near = rows(r as f32 - 2.0, r as f32 + 3.0).filter_map(|k| Some((k, self.at(c, k)?)));
        let (sum, weight) = near
            .filter(|&(_, s)| s >= peak / 2.0)
            .fold((0.0, 0.0), |(a, w), (k, s)| (a + (k as f64 + 0.5) * f64::from(s), w + f64::from(s)));
        (weight > 0.0).then(|| sum / weight)
    }
}
