//! The depth of a tracked point from its radial positions against travel (001 §2.3): `1/r` is
//! linear in the travel `T`, `1/r = (Z0 - T) / (f R)`, fitted by weighted least squares, the
//! depth's spread from the fit's covariance and residuals.

use crate::depth::{DepthParams, radial};

/// Adds a sample `(T, 1/r)` weighted by `1 / var(1/r) = r⁴ / σ²`.
pub(crate) fn add_sample(s: &mut [f64; 7], p: &DepthParams, at: [f32; 2], travelled_m: f64) {
    let (_, r) = radial(p, at);
    let r = f64::from(r);
    let w = r.powi(4) / f64::from(p.noise_px).powi(2);
    let (t, y) = (travelled_m, 1.0 / r);
    for (k, v) in [w, w * t, w * t * t, w * y, w * t * y, w * y * y, 1.0].into_iter().enumerate() {
        s[k] += v;
    }
}

/// Depth now and its standard deviation from the weighted line `1/r = a + b T`:
/// `Z0 = -a / b`, now `Z0 - T`, with the variance propagated from the fit's covariance, scaled
/// up by the residuals where they exceed the assumed noise (from the third sample on): a track
/// that jumped to a look-alike (a paving slab's corner one slab on) does not fit a line.
pub(crate) fn fit(s: &[f64; 7], now: f64) -> Option<(f32, f32)> {
    let [sw, st, stt, sy, sty, syy, n] = *s;
    let det = sw * stt - st * st;
    if det <= 0.0 {
        return None;
    }
    let b = (sw * sty - st * sy) / det;
    let a = (sy - b * st) / sw;
    if b >= 0.0 {
        return None;
    }
    // Covariance of (a, b): the inverse of [[Σw, ΣwT], [ΣwT, ΣwT²]].
    let (vaa, vbb, vab) = (stt / det, sw / det, -st / det);
    let z0 = -a / b;
    // dZ0/da = -1/b, dZ0/db = a/b².
    let (ga, gb) = (-1.0 / b, a / (b * b));
    let rss = syy - 2.0 * a * sy - 2.0 * b * sty + a * a * sw + 2.0 * a * b * st + b * b * stt;
    let scale = if n >= 3.0 { (rss / (n - 2.0)).max(1.0) } else { 1.0 };
    let var = scale * (ga * ga * vaa + gb * gb * vbb + 2.0 * ga * gb * vab);
    Some(((z0 - now) as f32, var.max(0.0).sqrt() as f32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::moravec::MoravecParams;

    #[test]
    fn exact_radial_positions_give_the_exact_depth_and_a_shrinking_spread() {
        let p = DepthParams {
            foe: [320.0, 240.0],
            focal_px: 500.0,
            patch: 11,
            startup_reach_px: 30.0,
            min_depth_m: 0.0,
            update_reach_px: 3.0,
            noise_px: 0.5,
            min_score: 0.9,
            recut_score: 0.99,
            register_reach_px: 0.0,
            moravec: MoravecParams::default(),
        };
        // A point 12 m ahead, 0.8 m left and 0.5 m down of the axis.
        let (z0, lateral) = (12.0f64, [0.8f64, 0.5]);
        let mut sums = [0.0; 7];
        let mut spreads = Vec::new();
        for k in 0..6 {
            let t = 0.5 * k as f64;
            let at = [
                320.0 + (500.0 * lateral[0] / (z0 - t)) as f32,
                240.0 + (500.0 * lateral[1] / (z0 - t)) as f32,
            ];
            add_sample(&mut sums, &p, at, t);
            if let Some((z, sd)) = fit(&sums, t) {
                assert!((f64::from(z) - (z0 - t)).abs() < 1e-3 * z0, "frame {k}: {z} vs {}", z0 - t);
                spreads.push(sd);
            }
        }
        assert_eq!(spreads.len(), 5);
        assert!(spreads.windows(2).all(|w| w[1] < w[0]), "{spreads:?}");
        // A point that does not move away from the FOE has no depth.
        let mut still = [0.0; 7];
        add_sample(&mut still, &p, [400.0, 300.0], 0.0);
        add_sample(&mut still, &p, [400.0, 300.0], 0.5);
        assert_eq!(fit(&still, 0.5), None);
    }
}
