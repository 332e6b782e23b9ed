//! A real camera's imperfections, applied after rendering: uneven lighting (vignetting) and
//! sensor noise. Noise is seeded by the run's seed and the frame's sequence number, so the same
//! run renders the same frames.

/// What to add to a clean render.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effects {
    /// Light at the image corners relative to the centre is `1 - vignetting`.
    pub vignetting: f64,
    /// Standard deviation of the additive noise, grey levels.
    pub noise_sd: f64,
    pub seed: u64,
}

impl Effects {
    pub fn none() -> Self {
        Self { vignetting: 0.0, noise_sd: 0.0, seed: 0 }
    }

    pub fn is_none(&self) -> bool {
        self.vignetting == 0.0 && self.noise_sd == 0.0
    }

    /// Applies the effects in place to a `width x height` image of `bpp` bytes per pixel.
    pub fn apply(&self, width: usize, height: usize, bpp: usize, seq: u64, pixels: &mut [u8]) {
        if self.is_none() {
            return;
        }
        let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
        let r2_max = cx * cx + cy * cy;
        let mut state = (self.seed ^ seq.wrapping_mul(0x9E37_79B9_7F4A_7C15)) | 1;
        // The sum of two uniforms on [-0.5, 0.5] has a standard deviation of 1/sqrt(6).
        let noise_scale = self.noise_sd * 6f64.sqrt();
        for (v, row) in pixels.chunks_exact_mut(width * bpp).take(height).enumerate() {
            let dy = v as f64 + 0.5 - cy;
            for (u, px) in row.chunks_exact_mut(bpp).enumerate() {
                let dx = u as f64 + 0.5 - cx;
                let gain = 1.0 - self.vignetting * (dx * dx + dy * dy) / r2_max;
                let noise = if self.noise_sd > 0.0 {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    let a = (state & 0xffff) as f64 / 65536.0;
                    let b = ((state >> 16) & 0xffff) as f64 / 65536.0;
                    (a + b - 1.0) * noise_scale
                } else {
                    0.0
                };
                for c in px.iter_mut() {
                    *c = (f64::from(*c) * gain + noise).round().clamp(0.0, 255.0) as u8;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(px: &[u8]) -> (f64, f64) {
        let n = px.len() as f64;
        let mean = px.iter().map(|&p| f64::from(p)).sum::<f64>() / n;
        (mean, (px.iter().map(|&p| (f64::from(p) - mean).powi(2)).sum::<f64>() / n).sqrt())
    }

    #[test]
    fn noise_has_the_asked_deviation_and_is_seeded_per_frame() {
        let fx = Effects { vignetting: 0.0, noise_sd: 4.0, seed: 9 };
        let mut a = vec![128u8; 640 * 480];
        fx.apply(640, 480, 1, 1, &mut a);
        let (mean, sd) = stats(&a);
        assert!((mean - 128.0).abs() < 0.05, "{mean}");
        assert!((sd - 4.0).abs() < 0.2, "{sd}");
        let mut b = vec![128u8; 640 * 480];
        fx.apply(640, 480, 1, 1, &mut b);
        assert_eq!(a, b, "same seed and frame: same noise");
        let mut c = vec![128u8; 640 * 480];
        fx.apply(640, 480, 1, 2, &mut c);
        assert_ne!(a, c, "another frame: other noise");
    }

    #[test]
    fn vignetting_darkens_the_corners_not_the_centre() {
        let fx = Effects { vignetting: 0.3, noise_sd: 0.0, seed: 0 };
        let mut img = vec![200u8; 64 * 48];
        fx.apply(64, 48, 1, 0, &mut img);
        assert_eq!(img[24 * 64 + 32], 200);
        assert!((f64::from(img[0]) - 200.0 * 0.7).abs() <= 3.0, "{}", img[0]);
        let mut clean = vec![77u8; 12];
        Effects::none().apply(4, 3, 1, 0, &mut clean);
        assert!(clean.iter().all(|&p| p == 77));
    }
}
