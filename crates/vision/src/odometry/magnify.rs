//! Where a reacquired template's match lies off the feature when the view magnifies it: moving
//! towards a feature makes its patch look bigger at the next stop, and the unscaled template
//! then locks on its texture (the gradients' weighted centre), not on its centre. The Moravec
//! operator's one-sided shifts leave that texture about half a pixel right of and below the
//! centre on average, so every reacquired feature slid outwards and the stereo at the new stop
//! ranged a point nearer than the one ranged at the old: steps came out about 1.4 % long. The
//! drift is predicted to first order from the patch's gradients and the view's local affine
//! map under the predicted motion, and taken off the match.

use super::rig::Rig;
use super::solve::Motion;
use crate::image::GrayBuf;

/// A point this near the floor lies on it (its patch is the floor's, foreshortened); any other
/// is taken on a surface facing the camera at its depth (walls along the way magnify more
/// across than that: their drift is under-corrected). The vision workers' obstacles start at
/// the same height (`obstacle_min_z_m` of `missions/odometry/003.toml`).
const FLOOR_M: f64 = 0.1;

/// A 2x2 matrix, rows `[[a, b], [c, d]]`.
pub type Mat2 = [[f64; 2]; 2];

const IDENTITY: Mat2 = [[1.0, 0.0], [0.0, 1.0]];

/// The Jacobian of the map from the old left image to the new one round the feature seen at
/// `at` (pixel centres at +0.5) whose robot-frame point is `point`, after `motion`: the
/// surface round it is the floor or a plane facing the camera. The identity where the map is
/// not defined (a neighbour behind the camera or over the horizon).
pub fn local_affine(rig: &Rig, at: [f32; 2], point: [f64; 3], motion: &Motion) -> Mat2 {
    let on_floor = point[2].abs() < FLOOR_M;
    let lift = |u: f64, v: f64| {
        let depth = if on_floor { rig.focal_px * rig.height_m / (v - rig.centre_px[1]) } else { point[0] };
        [
            depth,
            (rig.centre_px[0] - u) * depth / rig.focal_px + rig.baseline_m / 2.0,
            rig.height_m - (v - rig.centre_px[1]) * depth / rig.focal_px,
        ]
    };
    let (u, v) = (f64::from(at[0]), f64::from(at[1]));
    let map = |du: f64, dv: f64| {
        let p = lift(u + du, v + dv);
        if !(p[0] > 0.0 && p.iter().all(|c| c.is_finite())) {
            return None;
        }
        rig.project(motion.inverse_apply(p))
    };
    let (Some(l), Some(r), Some(t), Some(b)) = (map(-0.5, 0.0), map(0.5, 0.0), map(0.0, -0.5), map(0.0, 0.5))
    else {
        return IDENTITY;
    };
    let a = [[r[0] - l[0], b[0] - t[0]], [r[1] - l[1], b[1] - t[1]]];
    if a.iter().flatten().all(|c| c.is_finite()) && det(a).abs() > 1e-6 { a } else { IDENTITY }
}

/// How far (pixels, `[du, dv]`) the best match of `patch`, taken round its centre pixel, lies
/// from the true image of that centre when the view maps the old image to the new by `a` round
/// it: `δ = -A S⁻¹ Σ g gᵀ (A⁻¹ - I) t` over the patch's pixels at offsets `t` from the centre
/// with gradients `g` (`S = Σ g gᵀ`, the structure tensor). Zero for a patch without texture
/// in two directions.
pub fn drift(patch: &GrayBuf, a: Mat2) -> [f64; 2] {
    let d = det(a);
    let m = [[a[1][1] / d - 1.0, -a[0][1] / d], [-a[1][0] / d, a[0][0] / d - 1.0]];
    let img = patch.view();
    let (cx, cy) = ((img.width / 2) as f64, (img.height / 2) as f64);
    let (mut s, mut r) = ([0.0; 3], [0.0; 2]);
    let at = |i: usize, j: usize| f64::from(img.at(i, j));
    for j in 1..img.height.saturating_sub(1) {
        for i in 1..img.width.saturating_sub(1) {
            let g = [(at(i + 1, j) - at(i - 1, j)) / 2.0, (at(i, j + 1) - at(i, j - 1)) / 2.0];
            let t = [i as f64 - cx, j as f64 - cy];
            let gmt = g[0] * (m[0][0] * t[0] + m[0][1] * t[1]) + g[1] * (m[1][0] * t[0] + m[1][1] * t[1]);
            s = [s[0] + g[0] * g[0], s[1] + g[0] * g[1], s[2] + g[1] * g[1]];
            r = [r[0] + g[0] * gmt, r[1] + g[1] * gmt];
        }
    }
    let ds = s[0] * s[2] - s[1] * s[1];
    if ds.is_nan() || ds <= 1e-9 * (s[0] + s[2]).powi(2) {
        return [0.0; 2];
    }
    let w = [-(s[2] * r[0] - s[1] * r[1]) / ds, -(s[0] * r[1] - s[1] * r[0]) / ds];
    let out = [a[0][0] * w[0] + a[0][1] * w[1], a[1][0] * w[0] + a[1][1] * w[1]];
    if out.iter().all(|c| c.is_finite()) { out } else { [0.0; 2] }
}

fn det(a: Mat2) -> f64 {
    a[0][0] * a[1][1] - a[0][1] * a[1][0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nc::{Correlator, Template};

    /// A smooth blob off the patch's centre on a textured ground, drawn at scale `k` round the
    /// image point `(cx, cy)`.
    fn scene(k: f64, cx: f64, cy: f64) -> GrayBuf {
        GrayBuf::from_fn(96, 96, |x, y| {
            let (u, v) = ((x as f64 + 0.5 - cx) / k, (y as f64 + 0.5 - cy) / k);
            let blob = 120.0 * (-((u - 3.0).powi(2) + (v - 2.0).powi(2)) / 3.0).exp();
            let ridge = 40.0 * (-((u + v + 1.0).powi(2)) / 3.0).exp();
            (60.0 + blob + ridge).round() as u8
        })
    }

    #[test]
    fn a_magnified_patch_matches_off_its_centre_by_the_predicted_drift() {
        // The feature at pixel (40, 40) (centre 40.5), the view magnified 1.15x round it.
        let old = scene(1.0, 40.5, 40.5);
        let patch = GrayBuf::crop(&old.view(), crate::image::Rect::new(35, 35, 46, 46)).expect("crop");
        let new = scene(1.15, 48.5, 44.5);
        let template = Template::new(&patch).expect("template");
        let m = Correlator::default().best(&new.view(), new.view().full(), &template).expect("match");
        let found = [f64::from(m.centre[0]) - 48.5, f64::from(m.centre[1]) - 44.5];
        let d = drift(&patch, [[1.15, 0.0], [0.0, 1.15]]);
        // Uncorrected, the match sits on the blob's side, a quarter of a pixel off (0.26).
        assert!(found[0].hypot(found[1]) > 0.2, "{found:?}");
        let left = [found[0] - d[0], found[1] - d[1]];
        assert!(left[0].hypot(left[1]) < 0.4 * found[0].hypot(found[1]), "{found:?} - {d:?}");
        // No magnification, no drift.
        assert_eq!(drift(&patch, IDENTITY), [0.0, 0.0]);
    }

    #[test]
    fn the_floor_stretches_more_down_than_across_as_the_robot_nears_it() {
        let rig = super::super::rig::example();
        let ahead = Motion { x_m: 0.4, y_m: 0.0, heading_rad: 0.0 };
        // A floor point 3 m ahead of the left camera.
        let v = rig.centre_px[1] + rig.focal_px * rig.height_m / 3.0;
        let a =
            local_affine(&rig, [rig.centre_px[0] as f32, v as f32], [3.0, rig.baseline_m / 2.0, 0.0], &ahead);
        let k = 3.0 / 2.6;
        assert!((a[0][0] - k).abs() < 0.01 && (a[1][1] - k * k).abs() < 0.02, "{a:?}");
        // Off the axis the floor also shears: the map carries a neighbour three rows down to where
        // that floor point is seen after the step (an independent check of the matrix's layout).
        let (u, v) = (180.0, rig.centre_px[1] + rig.focal_px * rig.height_m / 3.0);
        let floor = |u: f64, v: f64| {
            let x = rig.focal_px * rig.height_m / (v - rig.centre_px[1]);
            [x, (rig.centre_px[0] - u) * x / rig.focal_px + rig.baseline_m / 2.0, 0.0]
        };
        let seen = |p: [f64; 3]| rig.project(ahead.inverse_apply(p)).expect("in front");
        let (p0, p1) = (seen(floor(u, v)), seen(floor(u, v + 3.0)));
        let a = local_affine(&rig, [u as f32, v as f32], floor(u, v), &ahead);
        let moved = [a[0][1] * 3.0, a[1][1] * 3.0];
        assert!(moved[0].abs() > 0.2, "the floor shears off the axis: {a:?}");
        for k in 0..2 {
            assert!(
                (moved[k] - (p1[k] - p0[k])).abs() < 0.03 * (p1[k] - p0[k]).abs(),
                "{a:?}: {p0:?} {p1:?}"
            );
        }
        // A wall point at 3 m magnifies alike both ways; a turn in place does not magnify.
        let a = local_affine(&rig, [200.0, 150.0], [3.0, 0.8, 1.5], &ahead);
        assert!((a[0][0] - k).abs() < 0.01 && (a[1][1] - k).abs() < 0.01, "{a:?}");
        let turn = Motion { x_m: 0.0, y_m: 0.0, heading_rad: 0.2 };
        let a = local_affine(&rig, [320.0, 150.0], [3.0, 0.125, 1.5], &turn);
        assert!((a[0][0] - 1.0).abs() < 0.05 && (a[1][1] - 1.0).abs() < 0.05, "{a:?}");
    }
}
