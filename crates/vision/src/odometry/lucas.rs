//! Lucas registration (003 "Motion Solving", after B. D. Lucas): every feature's patch of the
//! old left image is projected at once into the new one under a hypothesised planar motion (each
//! patch taken as a plane facing the camera at its feature's stereo depth) and the motion is
//! moved by Gauss-Newton to minimise the intensity differences, with the prediction as a prior.
//! It starts on a blurred, reduced image and goes finer level by level (the pyramid of 2x2
//! means), so the prediction may be off by more than the patch. Each patch's gain and offset are
//! fitted on every iteration (the light drifts between stops), and a pixel whose difference is
//! more than a few sigmas is down-weighted (Huber), so an occluded patch does not drag the rest.

use super::rig::Rig;
use super::solve::{Motion, Prior};
use crate::image::GrayBuf;

/// How the registration runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LucasParams {
    /// Pyramid levels (1: the full image only).
    pub levels: usize,
    /// Patch half-width at every level, pixels of that level.
    pub radius: usize,
    pub iterations: usize,
    /// Differences beyond this many standard deviations of the image's noise count linearly
    /// (Huber).
    pub huber: f64,
}

/// A feature of the old stop: its left-image position (pixel centres at +0.5) and robot-frame point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    pub at: [f32; 2],
    pub point: [f64; 3],
}

/// The registered motion and how many patches it used at the finest level.
#[derive(Debug, Clone, PartialEq)]
pub struct Registration {
    pub motion: Motion,
    pub covariance: [[f64; 3]; 3],
    pub patches: usize,
}

/// Registers `new` (pyramid levels, finest first) against `old` under `prior`, the images'
/// noise being `intensity_sd` grey levels (it weighs the differences against the prior).
pub fn register(
    rig: &Rig,
    old: &[GrayBuf],
    new: &[GrayBuf],
    anchors: &[Anchor],
    prior: &Prior,
    p: &LucasParams,
    intensity_sd: f64,
) -> Option<Registration> {
    let levels = p.levels.min(old.len()).min(new.len());
    let top = levels.checked_sub(1)?;
    // The heading is what a prediction gets most wrong, and a patch's basin on the coarsest
    // level is about a pixel of it: the headings within 3 sd of the prediction are tried a
    // coarse pixel apart and the registration starts from the one that fits best.
    let pixel = f64::from(1u32 << top) / rig.focal_px;
    let reach = (3.0 * prior.sd[2] / pixel).ceil() as i64;
    let mut m = (-reach..=reach)
        .map(|k| Motion { heading_rad: prior.motion.heading_rad + k as f64 * pixel, ..prior.motion })
        .map(|m| (m, normal_equations(rig, &old[top], &new[top], top, anchors, prior, &m, p, intensity_sd).3))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(prior.motion, |(m, _)| m);
    let mut last = None;
    for level in (0..levels).rev() {
        for _ in 0..p.iterations {
            let (h, g, patches, _) =
                normal_equations(rig, &old[level], &new[level], level, anchors, prior, &m, p, intensity_sd);
            let step = super::solve::solve3(h, g)?;
            m.x_m -= step[0];
            m.y_m -= step[1];
            m.heading_rad -= step[2];
            last = Some((h, patches));
            if step[0].hypot(step[1]) < 1e-5 && step[2].abs() < 1e-5 {
                break;
            }
        }
    }
    let (h, patches) = last?;
    Some(Registration { motion: m, covariance: super::solve::inverse3(h)?, patches })
}

/// The Gauss-Newton normal matrix and gradient at `m` on one level (prior included), how many
/// patches were inside both images, and the robust cost per pixel compared.
#[allow(clippy::too_many_arguments, reason = "one level's inputs, named")]
fn normal_equations(
    rig: &Rig,
    old: &GrayBuf,
    new: &GrayBuf,
    level: usize,
    anchors: &[Anchor],
    prior: &Prior,
    m: &Motion,
    p: &LucasParams,
    intensity_sd: f64,
) -> ([[f64; 3]; 3], [f64; 3], usize, f64) {
    let mut h = [[0.0; 3]; 3];
    let mut g = [0.0; 3];
    let pm = [prior.motion.x_m, prior.motion.y_m, prior.motion.heading_rad];
    let mm = [m.x_m, m.y_m, m.heading_rad];
    for k in 0..3 {
        h[k][k] = prior.sd[k].powi(-2);
        g[k] = h[k][k] * (mm[k] - pm[k]);
    }
    let scale = f64::from(1u32 << level);
    let r = p.radius as i64;
    let noise = intensity_sd.powi(-2);
    let (s, c) = m.heading_rad.sin_cos();
    let mut patches = 0;
    let (mut cost, mut compared) = (0.0, 0usize);
    let mut rows: Vec<(f64, f64, [f64; 3])> = Vec::with_capacity(((2 * r + 1) * (2 * r + 1)) as usize);
    for a in anchors {
        rows.clear();
        let depth = a.point[0];
        let (u0, v0) = (f64::from(a.at[0]) / scale, f64::from(a.at[1]) / scale);
        for j in -r..=r {
            for i in -r..=r {
                let (uo, vo) = (u0 + i as f64, v0 + j as f64);
                let Some((io, _, _)) = sample(old, uo, vo) else { continue };
                // The pixel's point on the plane facing the camera at the feature's depth.
                let (u, v) = (uo * scale, vo * scale);
                let pt = [
                    depth,
                    (rig.centre_px[0] - u) * depth / rig.focal_px + rig.baseline_m / 2.0,
                    rig.height_m - (v - rig.centre_px[1]) * depth / rig.focal_px,
                ];
                let (dx, dy) = (pt[0] - m.x_m, pt[1] - m.y_m);
                let (xn, yn) = (c * dx + s * dy, -s * dx + c * dy);
                if xn < 0.1 {
                    continue;
                }
                let un = (rig.centre_px[0] - rig.focal_px * (yn - rig.baseline_m / 2.0) / xn) / scale;
                let vn = (rig.centre_px[1] + rig.focal_px * (rig.height_m - pt[2]) / xn) / scale;
                let Some((inew, gu, gv)) = sample(new, un, vn) else { continue };
                // d(u, v) / d(x', y') at this level, then d(x', y') / d(motion).
                let du = [rig.focal_px * (yn - rig.baseline_m / 2.0) / (xn * xn), -rig.focal_px / xn];
                let dv = [-rig.focal_px * (rig.height_m - pt[2]) / (xn * xn), 0.0];
                let dxy = [[-c, -s, yn], [s, -c, -xn]];
                let j3: [f64; 3] = std::array::from_fn(|k| {
                    let du_k = du[0] * dxy[0][k] + du[1] * dxy[1][k];
                    let dv_k = dv[0] * dxy[0][k] + dv[1] * dxy[1][k];
                    (gu * du_k + gv * dv_k) / scale
                });
                rows.push((inew, io, j3));
            }
        }
        if rows.len() < 9 {
            continue;
        }
        patches += 1;
        // The patch's gain and offset: old ≈ gain * new + offset, by least squares.
        let n = rows.len() as f64;
        let (mn, mo) = (rows.iter().map(|r| r.0).sum::<f64>() / n, rows.iter().map(|r| r.1).sum::<f64>() / n);
        let var = rows.iter().map(|r| (r.0 - mn).powi(2)).sum::<f64>();
        let cov = rows.iter().map(|r| (r.0 - mn) * (r.1 - mo)).sum::<f64>();
        let gain = if var > 1e-9 { (cov / var).clamp(0.5, 2.0) } else { 1.0 };
        for &(inew, io, j3) in &rows {
            let res = gain * (inew - mn) - (io - mo);
            let knee = p.huber * intensity_sd;
            let w = noise * huber(res, knee);
            cost += if res.abs() <= knee { res * res } else { knee * (2.0 * res.abs() - knee) };
            compared += 1;
            for a in 0..3 {
                for b in 0..3 {
                    h[a][b] += w * gain * gain * j3[a] * j3[b];
                }
                g[a] += w * gain * j3[a] * res;
            }
        }
    }
    (h, g, patches, if compared == 0 { f64::INFINITY } else { cost / compared as f64 })
}

/// The Huber weight of a difference `r` with knee `k`.
fn huber(r: f64, k: f64) -> f64 {
    if r.abs() <= k { 1.0 } else { k / r.abs() }
}

/// The image's value and gradient (per pixel) at `(x, y)` (pixel centres at +0.5), bilinear;
/// `None` within a pixel and a half of the edge.
fn sample(img: &GrayBuf, x: f64, y: f64) -> Option<(f64, f64, f64)> {
    let (fx, fy) = (x - 0.5, y - 0.5);
    if !(fx >= 1.0 && fy >= 1.0 && fx < img.width as f64 - 2.0 && fy < img.height as f64 - 2.0) {
        return None;
    }
    let (ix, iy) = (fx.floor() as usize, fy.floor() as usize);
    let (ax, ay) = (fx - ix as f64, fy - iy as f64);
    let at = |x: usize, y: usize| f64::from(img.data[y * img.width + x]);
    let bilinear = |x: usize, y: usize| {
        (1.0 - ay) * ((1.0 - ax) * at(x, y) + ax * at(x + 1, y))
            + ay * ((1.0 - ax) * at(x, y + 1) + ax * at(x + 1, y + 1))
    };
    let value = bilinear(ix, iy);
    let gu = 0.5 * (bilinear(ix + 1, iy) - bilinear(ix - 1, iy));
    let gv = 0.5 * (bilinear(ix, iy + 1) - bilinear(ix, iy - 1));
    Some((value, gu, gv))
}
