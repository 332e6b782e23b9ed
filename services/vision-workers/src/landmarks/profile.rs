//! A window's vertical-edge profile in horizontal bands of rows: per band, each column's mean
//! level (sensor noise averages out over a band's rows), and per column the step across
//! `span` columns, its magnitude averaged over the bands. Banded, because a jamb's contrast
//! can change sign along its height (brighter than the wall above a door's lintel, darker
//! beside the door), which a mean over every row would cancel.

/// The share of a ramp's rise the levels either side of it must keep to make it a step.
const STEP_FRACTION: f32 = 0.75;

/// The banded profile of one window; buffers reused between frames.
#[derive(Debug, Default)]
pub struct Profile {
    bands: usize,
    /// Columns of the window.
    n: usize,
    /// Per band, each column's mean level relative to the band's first column (`bands * n`).
    levels: Vec<f32>,
    /// The levels' sums over each band's rows (scratch).
    sums: Vec<i32>,
    /// Per column `k`, the step from `k` to `k + span`: its magnitude averaged over the bands.
    pub strength: Vec<f32>,
}

impl Profile {
    /// Reads the window `[u0, v0, u1, v1)` (already clipped to the frame, at least `span + 2`
    /// columns) of a frame's first channel in bands of about `band_rows` rows; returns the
    /// window's mean grey level and the rows per band.
    pub fn fill(
        &mut self,
        pixels: &[u8],
        stride: usize,
        bpp: usize,
        [u0, v0, u1, v1]: [usize; 4],
        band_rows: usize,
    ) -> (f32, f32) {
        let rows = v1 - v0;
        self.n = u1 - u0;
        self.bands = (rows / band_rows.max(1)).max(1);
        // Summed as integers (mono8 rows vectorise): the values an f32 sum takes, exact while
        // a band's sums stay under 2^24 (255 x 65 793 rows).
        self.sums.clear();
        self.sums.resize(self.bands * self.n, 0);
        let mut brightness = 0u64;
        for (r, row) in pixels.chunks_exact(stride).skip(v0).take(rows).enumerate() {
            let band = r * self.bands / rows;
            let sums = &mut self.sums[band * self.n..(band + 1) * self.n];
            let first = i32::from(row[u0 * bpp]);
            if bpp == 1 {
                for (sum, &p) in sums.iter_mut().zip(&row[u0..u0 + self.n]) {
                    *sum += i32::from(p) - first;
                    brightness += u64::from(p);
                }
            } else {
                for (k, sum) in sums.iter_mut().enumerate() {
                    let p = row[(u0 + k) * bpp];
                    *sum += i32::from(p) - first;
                    brightness += u64::from(p);
                }
            }
        }
        self.levels.clear();
        for band in 0..self.bands {
            let band_rows = ((band + 1) * rows / self.bands - band * rows / self.bands) as f32;
            let sums = &self.sums[band * self.n..(band + 1) * self.n];
            self.levels.extend(sums.iter().map(|&sum| sum as f32 / band_rows));
        }
        (brightness as f32 / (rows * self.n) as f32, rows as f32 / self.bands as f32)
    }

    fn band(&self, b: usize) -> &[f32] {
        &self.levels[b * self.n..(b + 1) * self.n]
    }

    /// Fills `strength` for steps across `span` columns, less `floor` (what noise alone gives).
    pub fn strengths(&mut self, span: usize, floor: f32) {
        let columns = self.n.saturating_sub(span);
        let mut strength = std::mem::take(&mut self.strength);
        strength.clear();
        strength.extend((0..columns).map(|k| {
            let sum: f32 = (0..self.bands).map(|b| (self.band(b)[k + span] - self.band(b)[k]).abs()).sum();
            (sum / self.bands as f32 - floor).max(0.0)
        }));
        self.strength = strength;
    }

    /// Whether the ramp from `k` to `k + span` is a step: in each band, the level over
    /// `2 span` columns beyond it differs from the level over `2 span` columns before it, in the
    /// ramp's direction, by at least `STEP_FRACTION` of the ramp's rise (summed over the bands).
    /// A thin bright or dark line (trim, a gap) rises and falls within a few columns and is not
    /// a step.
    /// An edge too near the window's side for a full plateau beside it (one sliding in from
    /// outside the window) is not taken.
    pub fn is_step(&self, k: usize, span: usize) -> bool {
        if k + 1 < 2 * span || k + 3 * span > self.n {
            return false;
        }
        let mean = |l: &[f32], from: usize, to: usize| l[from..to].iter().sum::<f32>() / (to - from) as f32;
        let (mut along, mut rise) = (0.0, 0.0);
        for b in 0..self.bands {
            let l = self.band(b);
            let ramp = l[k + span] - l[k];
            let plateaus = mean(l, k + span, k + 3 * span) - mean(l, k + 1 - 2 * span, k + 1);
            along += plateaus * ramp.signum();
            rise += ramp.abs();
        }
        rise > 0.0 && along >= STEP_FRACTION * rise
    }

    /// The share of the bands in which the ramp from `k` to `k + span` rises or falls by at
    /// least `min_step`: a landmark's vertical line spans the window (the Expecter sizes it to
    /// the landmark's height), a sign's or a notice board's side only part of it.
    pub fn coverage(&self, k: usize, span: usize, min_step: f32) -> f32 {
        let present =
            (0..self.bands).filter(|&b| (self.band(b)[k + span] - self.band(b)[k]).abs() >= min_step).count();
        present as f32 / self.bands as f32
    }

    /// How the ramp from `k` to `k + span` agrees with a predicted look (`contrast`: the step
    /// right less left in equal bands of the window's rows, top first), from -1 to 1: each
    /// band's signed step weighed by the prediction for the rows it lies in, summed, over the
    /// same of their magnitudes. -1: the edge runs the other way from the landmark's in every
    /// band the prediction weighs (a look-alike); 0 where nothing is predicted.
    pub fn agreement(&self, k: usize, span: usize, contrast: &[f32]) -> f32 {
        let parts = contrast.len() as f32;
        let (along, all) = (0..self.bands)
            .map(|b| {
                let part = ((b as f32 + 0.5) / self.bands as f32 * parts) as usize;
                let l = self.band(b);
                let (c, step) = (contrast[part.min(contrast.len() - 1)], l[k + span] - l[k]);
                (c * step, (c * step).abs())
            })
            .fold((0.0, 0.0), |(a, m), (x, y)| (a + x, m + y));
        if all > 0.0 { along / all } else { 0.0 }
    }

    /// Where the edge whose ramp starts at column `k` lies, in columns from the window's first
    /// boundary (the one between its columns 0 and 1): the centroid of the single-column steps
    /// along each band's ramp direction, each less a quarter of the largest (a sharp edge:
    /// exactly the boundary it is on, whatever the shading beside it).
    pub fn edge_at(&self, k: usize, span: usize) -> f64 {
        let weight = |j: usize| -> f64 {
            (0..self.bands)
                .map(|b| {
                    let l = self.band(b);
                    f64::from(((l[j + 1] - l[j]) * (l[k + span] - l[k]).signum()).max(0.0))
                })
                .sum()
        };
        let floor = 0.25 * (k..k + span).map(weight).fold(0.0, f64::max);
        let (sum, moment) = (k..k + span)
            .map(|j| ((weight(j) - floor).max(0.0), j))
            .fold((0.0, 0.0), |(s, m), (w, j)| (s + w, m + w * j as f64));
        if sum > 0.0 { moment / sum } else { k as f64 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 8 columns, 32 rows of 100 left of column 4; right of it 130 above row 16, `below` under.
    fn flipping(below: u8) -> Vec<u8> {
        (0..8 * 32)
            .map(|i| {
                if i % 8 < 4 {
                    100
                } else if i / 8 < 16 {
                    130
                } else {
                    below
                }
            })
            .collect()
    }

    #[test]
    fn a_jamb_whose_contrast_flips_along_its_height_is_still_an_edge() {
        // Above row 16 the edge at column 4 is +30, below it -30.
        let f = flipping(70);
        let mut p = Profile::default();
        let (mean, rows_per_band) = p.fill(&f, 8, 1, [0, 0, 8, 32], 16);
        assert_eq!((mean, rows_per_band), (100.0, 16.0));
        p.strengths(1, 0.0);
        assert_eq!(p.strength[3], 30.0, "both halves count: {:?}", p.strength);
        assert!(p.is_step(3, 1));
        assert_eq!(p.edge_at(3, 1), 3.0);
        // One band: the halves cancel.
        p.fill(&f, 8, 1, [0, 0, 8, 32], 32);
        p.strengths(1, 0.0);
        assert_eq!(p.strength[3], 0.0);
    }

    #[test]
    fn an_edge_agrees_with_the_look_predicted_for_it_not_with_the_reverse() {
        // A rise at column 4 in the top half, a fall in the bottom half.
        let f = flipping(90);
        let mut p = Profile::default();
        p.fill(&f, 8, 1, [0, 0, 8, 32], 8);
        assert_eq!(p.agreement(3, 1, &[0.3, 0.3, -0.1, -0.1]), 1.0);
        assert_eq!(p.agreement(3, 1, &[-0.3, -0.3, 0.1, 0.1]), -1.0);
        // Weighed by the prediction: a strong rise predicted above outweighs a weak fall below
        // ((18 - 2) / (18 + 2)).
        assert!((p.agreement(3, 1, &[0.3, 0.3, 0.1, 0.1]) - 0.8).abs() < 1e-6);
        assert_eq!(p.agreement(3, 1, &[0.0; 4]), 0.0);
    }

    #[test]
    fn a_thin_line_is_not_a_step_and_a_ramp_is_centred() {
        // 16 columns: a two-column bright line at columns 8-9 of 100.
        let line: Vec<u8> =
            (0..16 * 4).map(|i| if (8..10).contains(&(i % 16)) { 140 } else { 100 }).collect();
        let mut p = Profile::default();
        p.fill(&line, 16, 1, [0, 0, 16, 4], 4);
        p.strengths(3, 0.0);
        assert_eq!((p.strength[5], p.strength[6]), (40.0, 40.0));
        assert!((5..=7).all(|k| !p.is_step(k, 3)), "rises and falls within three columns");
        // A ramp 100 -> 130 over the boundaries after columns 5, 6 and 7.
        let ramp: Vec<u8> = (0..16 * 4).map(|i| [100, 110, 120, 130][(i % 16).clamp(5, 8) - 5]).collect();
        p.fill(&ramp, 16, 1, [0, 0, 16, 4], 4);
        p.strengths(3, 0.0);
        assert_eq!(p.strength[5], 30.0);
        assert!(p.is_step(5, 3));
        assert!(!p.is_step(1, 3) && !p.is_step(12, 3), "too near the window's side for a plateau");
        assert_eq!(p.edge_at(5, 3), 6.0, "the middle step of the ramp: between columns 6 and 7");
    }

    #[test]
    fn an_rgb_window_gives_what_its_first_channel_as_mono_gives() {
        // A window inside a 23-column frame, away from its corner, three bands of uneven rows.
        let grey = |i: usize| ((i % 23) * 9 + (i / 23) * 5 % 7) as u8;
        let mono: Vec<u8> = (0..23 * 20).map(grey).collect();
        let rgb: Vec<u8> = (0..23 * 20).flat_map(|i| [grey(i), 255 - grey(i), 7]).collect();
        let (mut a, mut b) = (Profile::default(), Profile::default());
        let window = [3, 2, 21, 19];
        assert_eq!(a.fill(&mono, 23, 1, window, 5), b.fill(&rgb, 69, 3, window, 5));
        assert_eq!(a.levels, b.levels);
        assert_eq!(a.levels.len(), 3 * 18);
        assert!(a.levels.iter().any(|&l| l != 0.0));
    }
}
