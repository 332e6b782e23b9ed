//! A real camera's imperfections, applied after rendering: optical blur, the light's slow change
//! over a run, uneven lighting (vignetting) and sensor noise. Noise is seeded by the run's seed
//! and the frame's sequence number, the light's phase by the seed, so the same run renders the
//! same frames.

use harvey_geometry::Rng;
use harvey_world::Camera;

/// Seeds the light's phase apart from the other draws made from the run's seed.
const LIGHT_STREAM: u64 = 0x6c69_6768_7473;

/// Seeds the camera mount's misalignment apart from the other draws.
const MOUNT_STREAM: u64 = 0x006d_6f75_6e74;

/// The camera mount's true yaw (left positive) and pitch (down positive) for a run of `seed`,
/// radians: the world's `mount_error_rad` when it gives one, else each a normal draw of its
/// `misalignment_sd_rad`; unknown to the robot.
pub fn mount_error(c: &Camera, seed: u64) -> (f64, f64) {
    if let Some([yaw, pitch]) = c.mount_error_rad {
        return (yaw, pitch);
    }
    if c.misalignment_sd_rad == 0.0 {
        return (0.0, 0.0);
    }
    let mut rng = Rng::new(seed ^ MOUNT_STREAM);
    (rng.normal(0.0, c.misalignment_sd_rad), rng.normal(0.0, c.misalignment_sd_rad))
}

/// What to add to a clean render.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effects {
    /// Light at the image corners relative to the centre is `1 - vignetting`.
    pub vignetting: f64,
    /// Standard deviation of the additive noise, grey levels.
    pub noise_sd: f64,
    pub seed: u64,
    /// The light swings by this fraction either way over `period_s`.
    pub drift: f64,
    pub period_s: f64,
    /// Box-blur radius, pixels.
    pub blur_px: u32,
}

impl Effects {
    pub fn none() -> Self {
        Self::noisy(0.0, 0.0, 0)
    }

    /// Vignetting and noise only.
    pub fn noisy(vignetting: f64, noise_sd: f64, seed: u64) -> Self {
        Self { vignetting, noise_sd, seed, drift: 0.0, period_s: 1.0, blur_px: 0 }
    }

    /// The imperfections a world's `[camera]` asks for, for a run of `seed`.
    pub fn from_camera(c: &Camera, seed: u64) -> Self {
        Self {
            vignetting: c.vignetting,
            noise_sd: c.noise_sd,
            seed,
            drift: c.illumination_drift,
            period_s: c.illumination_period_s,
            blur_px: c.blur_px,
        }
    }

    pub fn is_none(&self) -> bool {
        self.vignetting == 0.0 && self.noise_sd == 0.0 && self.drift == 0.0 && self.blur_px == 0
    }

    /// The light at `stamp_ns` relative to the world's illumination.
    pub fn light_at(&self, stamp_ns: u64) -> f64 {
        if self.drift == 0.0 {
            return 1.0;
        }
        let phase = std::f64::consts::TAU * Rng::new(self.seed ^ LIGHT_STREAM).unit();
        let t = stamp_ns as f64 * 1e-9;
        1.0 + self.drift * (std::f64::consts::TAU * t / self.period_s + phase).sin()
    }

    /// [`Effects::apply_at`] at time zero.
    pub fn apply(&self, width: usize, height: usize, bpp: usize, seq: u64, pixels: &mut [u8]) {
        self.apply_at(width, height, bpp, seq, 0, pixels);
    }

    /// Applies the effects in place to a `width x height` image of `bpp` bytes per pixel, frame
    /// `seq` taken at `stamp_ns`.
    pub fn apply_at(
        &self,
        width: usize,
        height: usize,
        bpp: usize,
        seq: u64,
        stamp_ns: u64,
        pixels: &mut [u8],
    ) {
        if self.is_none() {
            return;
        }
        if self.blur_px > 0 {
            crate::blur::box_blur(width, height, bpp, self.blur_px as usize, pixels);
        }
        let light = self.light_at(stamp_ns);
        let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
        let r2_max = cx * cx + cy * cy;
        let mut state = (self.seed ^ seq.wrapping_mul(0x9E37_79B9_7F4A_7C15)) | 1;
        // The sum of two uniforms on [-0.5, 0.5] has a standard deviation of 1/sqrt(6).
        let noise_scale = self.noise_sd * 6f64.sqrt();
        for (v, row) in pixels.chunks_exact_mut(width * bpp).take(height).enumerate() {
            let dy = v as f64 + 0.5 - cy;
            for (u, px) in row.chunks_exact_mut(bpp).enumerate() {
                let dx = u as f64 + 0.5 - cx;
                let gain = light * (1.0 - self.vignetting * (dx * dx + dy * dy) / r2_max);
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
    fn a_mount_error_given_is_taken_exactly_and_a_spread_is_drawn_per_seed() {
        let w =
            harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("world");
        let mut c = w.camera.clone();
        let (a, b) = (mount_error(&c, 1), mount_error(&c, 2));
        assert!(a != b && a.0.abs() < 0.02 && a.1.abs() < 0.02, "{a:?} {b:?}");
        assert_eq!(mount_error(&c, 1), a, "seeded");
        c.mount_error_rad = Some([0.01, -0.002]);
        assert_eq!((mount_error(&c, 1), mount_error(&c, 2)), ((0.01, -0.002), (0.01, -0.002)));
        c.mount_error_rad = None;
        c.misalignment_sd_rad = 0.0;
        assert_eq!(mount_error(&c, 1), (0.0, 0.0));
    }

    #[test]
    fn noise_has_the_asked_deviation_and_is_seeded_per_frame() {
        let fx = Effects::noisy(0.0, 4.0, 9);
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
        let fx = Effects::noisy(0.3, 0.0, 0);
        let mut img = vec![200u8; 64 * 48];
        fx.apply(64, 48, 1, 0, &mut img);
        assert_eq!(img[24 * 64 + 32], 200);
        assert!((f64::from(img[0]) - 200.0 * 0.7).abs() <= 3.0, "{}", img[0]);
        let mut clean = vec![77u8; 12];
        Effects::none().apply(4, 3, 1, 0, &mut clean);
        assert!(clean.iter().all(|&p| p == 77));
    }

    #[test]
    fn the_light_swings_by_the_drift_over_its_period() {
        let fx = Effects { drift: 0.2, period_s: 60.0, ..Effects::noisy(0.0, 0.0, 4) };
        let lights: Vec<f64> = (0..600).map(|i| fx.light_at(i * 100_000_000)).collect();
        let (lo, hi) = lights.iter().fold((f64::MAX, f64::MIN), |(a, b), &l| (a.min(l), b.max(l)));
        assert!((hi - 1.2).abs() < 1e-3 && (lo - 0.8).abs() < 1e-3, "{lo}..{hi}");
        assert!((fx.light_at(0) - fx.light_at(60_000_000_000)).abs() < 1e-9, "periodic");
        assert_ne!(fx.light_at(0), Effects { seed: 5, ..fx }.light_at(0), "the phase is seeded");
        let mut img = vec![200u8; 16];
        let t_dark =
            (0..600).map(|i| i * 100_000_000).min_by(|&a, &b| fx.light_at(a).total_cmp(&fx.light_at(b)));
        fx.apply_at(4, 4, 1, 0, t_dark.expect("some"), &mut img);
        assert!(img.iter().all(|&p| p == 160), "{img:?}");
    }
}
