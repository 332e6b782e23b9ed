//! The Moravec corners as interest rows stream in: a pixel is a corner when its interest is at
//! or above the threshold, no interest within `r` (a square) is larger, and on a plateau it is
//! the first in scan order. Each row's maxima over `x - r ..= x + r`, and the pixels that top
//! their row window, are kept in a ring of the last `2r + 1` rows; such a pixel is a corner when
//! the rows above and below agree at its column, so no whole-frame map is written or read.
//!
//! Interest rows sit in the ring with `r` zeros either side, so the row maxima need no edge
//! cases. The row pass has AVX-512 and AVX2 forms (`peaks_simd.rs`) and a portable twin
//! (`peaks_portable.rs`).

use super::Corner;
use super::interest::RowSink;
use crate::simd::Path;

/// Ring buffers of the last `2r + 1` interest rows (padded), their row-window maxima, and the
/// pixels at or above the threshold that top their row window.
#[derive(Debug, Default)]
pub(super) struct Peaks {
    /// Padded rows: `r` zeros, the row's `width` values, `r` zeros.
    interest: Vec<u32>,
    across: Vec<u32>,
    tops: Vec<Vec<u32>>,
    /// Scratch: where the maxima of the rows round the one being finished start.
    offsets: Vec<usize>,
    /// Scratch of the portable row pass (`peaks_portable.rs`).
    spans: [Vec<u32>; 2],
    width: usize,
    height: usize,
    r: usize,
    threshold: u32,
    /// Where the window starts in the image (corners are reported in image coordinates).
    origin: (usize, usize),
    /// The instruction-set path of the row pass.
    path: Option<Path>,
}

impl Peaks {
    /// Ready for a `width x height` window at `origin`; `threshold` is at least 1.
    pub(super) fn start(
        &mut self,
        width: usize,
        height: usize,
        origin: (usize, usize),
        r: usize,
        threshold: u32,
        path: Path,
    ) {
        self.path = Some(path);
        let slots = 2 * r + 1;
        (self.width, self.height, self.r, self.threshold, self.origin) =
            (width, height, r, threshold.max(1), origin);
        self.interest.clear();
        self.interest.resize(slots * self.stride(), 0);
        self.across.clear();
        self.across.resize(slots * width, 0);
        self.tops.resize_with(slots.max(self.tops.len()), Vec::new);
    }

    /// The length of a padded ring row.
    fn stride(&self) -> usize {
        self.width + 2 * self.r
    }

    fn slot(&self, y: usize) -> usize {
        y % (2 * self.r + 1)
    }

    /// The row pass over ring row `y`: its window maxima and its tops.
    fn scan(&mut self, y: usize) {
        let (s, ww, r, t) = (self.slot(y), self.width, self.r, self.threshold);
        let row = &self.interest[s * self.stride()..][..self.stride()];
        let across = &mut self.across[s * ww..(s + 1) * ww];
        let tops = &mut self.tops[s];
        tops.clear();
        let path = self.path.unwrap_or_else(Path::active);
        super::peaks_simd::scan(path, row, r, t, across, tops, &mut self.spans);
    }

    /// Appends the corners of row `y` (all of rows `y - r ..= y + r` that exist are in the ring).
    fn finish_row(&mut self, y: usize, corners: &mut Vec<Corner>) {
        let (s, ww, r) = (self.slot(y), self.width, self.r);
        if self.tops[s].is_empty() {
            return;
        }
        // Where the maxima of the rows above and below start in `across` (one division per
        // row, not per top).
        let mut offsets = std::mem::take(&mut self.offsets);
        offsets.clear();
        offsets.extend((y.saturating_sub(r)..=(y + r).min(self.height - 1)).map(|j| self.slot(j) * ww));
        let (above, below) = offsets.split_at(y - y.saturating_sub(r));
        let below = &below[1..];
        let row = &self.interest[s * self.stride()..][..self.stride()];
        for &x in &self.tops[s] {
            let x = x as usize;
            let v = row[r + x];
            // Nothing before it in scan order equals it (nothing in the window exceeds it).
            if !row[x..r + x].contains(&v)
                && above.iter().all(|&o| self.across[o + x] < v)
                && below.iter().all(|&o| self.across[o + x] <= v)
            {
                corners.push(Corner { x: self.origin.0 + x, y: self.origin.1 + y, interest: v });
            }
        }
        self.offsets = offsets;
    }

    /// Call after the last row: the corners of the rows still waiting for rows below them.
    pub(super) fn finish(&mut self, corners: &mut Vec<Corner>) {
        for y in self.height.saturating_sub(self.r)..self.height {
            self.finish_row(y, corners);
        }
    }
}

/// [`Peaks`] with the list the corners go to, as the sink of the interest rows.
pub(super) struct PeakSink<'a> {
    pub(super) peaks: &'a mut Peaks,
    pub(super) corners: &'a mut Vec<Corner>,
}

impl RowSink for PeakSink<'_> {
    fn row(&mut self, y: usize) -> &mut [u32] {
        let p = &mut *self.peaks;
        let (s, stride, r, ww) = (p.slot(y), p.stride(), p.r, p.width);
        &mut p.interest[s * stride + r..][..ww]
    }

    fn done(&mut self, y: usize) {
        self.peaks.scan(y);
        if y >= self.peaks.r {
            self.peaks.finish_row(y - self.peaks.r, self.corners);
        }
    }
}
