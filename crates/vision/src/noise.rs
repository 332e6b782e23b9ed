//! The image's own noise level, estimated robustly from the window itself: the median gradient
//! magnitude of a grid of 2x2 cells. Flat surfaces dominate a scene, and on them the gradient is
//! the sensor noise alone (a Rayleigh magnitude whose median is 1.177 sigma for a noise of sigma
//! per pixel, with the 2x2 cell's halved sums), so thresholds can sit a few sigma above it
//! whatever the camera (dim, noisy, vignetted) instead of at a fixed grey level.

use std::sync::OnceLock;

use crate::image::{Gray, Rect};
use crate::regions::{TABLED, doubled_square, magnitude};

/// Median of a Rayleigh magnitude, in units of the per-component sigma: sqrt(2 ln 2).
const RAYLEIGH_MEDIAN: f32 = 1.177_410_1;

/// Every how many cells, across and down, one is sampled.
const STRIDE: usize = 3;

/// Histogram bins: gradient magnitudes to a quarter grey level, the last taking all above.
const BINS: usize = 1024;

/// The per-pixel noise sigma (grey levels) of `w` in `img` (the part inside the image),
/// estimated from the median cell gradient; 0 for a window too small to sample (under 2x2
/// pixels).
pub fn noise_sigma(img: &Gray<'_>, w: Rect) -> f32 {
    let w = Rect::new(w.x0, w.y0, w.x1.min(img.width), w.y1.min(img.height));
    if w.x1 < w.x0 + 2 || w.y1 < w.y0 + 2 {
        return 0.0;
    }
    // Gradient magnitudes to a quarter grey level, capped: the median of a noisy scene sits far
    // below the cap.
    let mut histogram = [0u32; BINS];
    let table = table();
    let mut n = 0u32;
    for y in (w.y0..w.y1 - 1).step_by(STRIDE) {
        let (r0, r1) = (&img.row(y)[w.x0..w.x1], &img.row(y + 1)[w.x0..w.x1]);
        for x in (0..w.width() - 1).step_by(STRIDE) {
            let s = doubled_square([r0[x], r0[x + 1], r1[x], r1[x + 1]]);
            histogram[table.get(s).map_or_else(|| bin(s), |&b| usize::from(b))] += 1;
            n += 1;
        }
    }
    let mut seen = 0;
    for (bin, &count) in histogram.iter().enumerate() {
        seen += count;
        if 2 * seen >= n {
            return (bin as f32 + 0.5) / 4.0 / RAYLEIGH_MEDIAN;
        }
    }
    0.0
}

/// The histogram bin of a 2x2 cell whose doubled gradient components square-sum to `s`
/// (`regions::doubled_square`): its magnitude (`regions::magnitude`, the one `cell_gradient`
/// gives) times 4, truncated, capped.
fn bin(s: usize) -> usize {
    ((magnitude(s) * 4.0) as usize).min(BINS - 1)
}

/// [`bin`] for every `s` under [`TABLED`] (a magnitude under 32 grey levels: all of the noise,
/// most of a scene), worked out once: the square root and the float-to-integer conversion were
/// the estimate's cost.
fn table() -> &'static [u16; TABLED] {
    static TABLE: OnceLock<[u16; TABLED]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|s| bin(s) as u16))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::GrayBuf;

    fn noisy(sigma: f64, seed: u64) -> GrayBuf {
        let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (width, height) = (160, 120);
        // A flat grey scene with one strong vertical edge: the edge must not count as noise.
        let data = (0..width * height)
            .map(|i| {
                let base = if i % width < 80 { 100.0 } else { 180.0 };
                // Twelve uniforms less six: a standard normal, near enough.
                let z = (0..12).map(|_| uniform()).sum::<f64>() - 6.0;
                (base + sigma * z).round().clamp(0.0, 255.0) as u8
            })
            .collect();
        GrayBuf { width, height, data }
    }

    #[test]
    fn the_estimate_follows_the_noise_and_ignores_the_edges() {
        for sigma in [0.0, 3.0, 8.0] {
            let img = noisy(sigma, 7);
            let g = img.view();
            let est = noise_sigma(&g, Rect::new(0, 0, 160, 120));
            assert!((f64::from(est) - sigma).abs() < 0.15 * sigma + 0.2, "sigma {sigma}: estimated {est}");
        }
        let img = noisy(3.0, 1);
        assert_eq!(noise_sigma(&img.view(), Rect::new(5, 5, 6, 6)), 0.0, "a single pixel");
        // A window reaching past the image: its part inside, no panic.
        let (g, inside) = (img.view(), Rect::new(100, 60, 160, 120));
        assert_eq!(noise_sigma(&g, Rect::new(100, 60, 500, 400)), noise_sigma(&g, inside));
        assert_eq!(noise_sigma(&g, Rect::new(159, 10, 300, 20)), 0.0, "one column inside");
    }

    #[test]
    fn every_cell_gets_the_bin_of_its_gradient_magnitude() {
        // All the doubled components a 2x2 cell of bytes can have, against the magnitude the
        // line finder's regions use, to a quarter grey level: the table and the square root
        // agree with it everywhere.
        let table = table();
        for gx2 in -510i32..=510 {
            for gy2 in -510i32..=510 {
                let (gx, gy) = (gx2 as f32 / 2.0, gy2 as f32 / 2.0);
                let want = (((gx * gx + gy * gy).sqrt() * 4.0) as usize).min(BINS - 1);
                let s = (gx2 * gx2 + gy2 * gy2) as usize;
                assert_eq!(bin(s), want, "({gx2}, {gy2})");
                if let Some(&b) = table.get(s) {
                    assert_eq!(usize::from(b), want, "({gx2}, {gy2}) tabled");
                }
            }
        }
    }
}
