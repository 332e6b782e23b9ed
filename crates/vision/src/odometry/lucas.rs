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
    let level_patches = |level: usize| patches(rig, &old[level], level, anchors, p.radius);
    // The heading is what a prediction gets most wrong, and a patch's basin on the coarsest
    // level is about a pixel of it: the headings within 3 sd of the prediction are tried a
    // coarse pixel apart and the registration starts from the one that fits best.
    let coarse = level_patches(top);
    let pixel = f64::from(1u32 << top) / rig.focal_px;
    let reach = (3.0 * prior.sd[2] / pixel).ceil() as i64;
    let mut m = (-reach..=reach)
        .map(|k| Motion { heading_rad: prior.motion.heading_rad + k as f64 * pixel, ..prior.motion })
        .map(|m| (m, normal_equations(rig, &new[top], top, &coarse, prior, &m, p, intensity_sd).3))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(prior.motion, |(m, _)| m);
    let mut last = None;
    for level in (0..levels).rev() {
        let here = if level == top { None } else { Some(level_patches(level)) };
        let samples = here.as_deref().unwrap_or(&coarse);
        // Converged once a step moves a point 4 m away by a hundredth of this level's pixel.
        let pixel = f64::from(1u32 << level) / rig.focal_px;
        let (metres, radians) = (0.04 * pixel, 0.01 * pixel);
        for _ in 0..p.iterations {
            let (h, g, patches, _) =
                normal_equations(rig, &new[level], level, samples, prior, &m, p, intensity_sd);
            let step = super::solve::solve3(h, g)?;
            m.x_m -= step[0];
            m.y_m -= step[1];
            m.heading_rad -= step[2];
            last = Some((h, patches));
            if step[0].hypot(step[1]) < metres && step[2].abs() < radians {
                break;
            }
        }
    }
    let (h, patches) = last?;
    Some(Registration { motion: m, covariance: super::solve::inverse3(h)?, patches })
}

/// One pixel of a patch: its point on the plane facing the camera at the feature's depth
/// (robot frame of the old stop) and its grey level in the old image.
#[derive(Debug, Clone, Copy)]
struct Sample {
    point: [f64; 3],
    old: f64,
}

/// Each anchor's patch on `level` of the old image (pixels inside it only).
fn patches(rig: &Rig, old: &GrayBuf, level: usize, anchors: &[Anchor], radius: usize) -> Vec<Vec<Sample>> {
    let scale = f64::from(1u32 << level);
    let r = radius as i64;
    anchors
        .iter()
        .map(|a| {
            let depth = a.point[0];
            let (u0, v0) = (f64::from(a.at[0]) / scale, f64::from(a.at[1]) / scale);
            (-r..=r)
                .flat_map(|j| (-r..=r).map(move |i| (u0 + i as f64, v0 + j as f64)))
                .filter_map(|(uo, vo)| {
                    let (old, _, _) = sample(old, uo, vo)?;
                    let (u, v) = (uo * scale, vo * scale);
                    let point = [
                        depth,
                        (rig.centre_px[0] - u) * depth / rig.focal_px + rig.baseline_m / 2.0,
                        rig.height_m - (v - rig.centre_px[1]) * depth / rig.focal_px,
                    ];
                    Some(Sample { point, old })
                })
                .collect()
        })
        .collect()
}

/// The Gauss-Newton normal matrix and gradient at `m` on one level (prior included), how many
/// patches were inside both images, and the robust cost per pixel compared.
#[allow(clippy::too_many_arguments, reason = "one level's inputs, named")]
fn normal_equations(
    rig: &Rig,
    new: &GrayBuf,
    level: usize,
    patches: &[Vec<Sample>],
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
    let noise = intensity_sd.powi(-2);
    let knee = p.huber * intensity_sd;
    let (s, c) = m.heading_rad.sin_cos();
    let (f, half_b) = (rig.focal_px, rig.baseline_m / 2.0);
    let mut used = 0;
    let (mut cost, mut compared) = (0.0, 0usize);
    let mut rows: Vec<(f64, f64, [f64; 3])> = Vec::new();
    for patch in patches {
        rows.clear();
        for &Sample { point: pt, old: io } in patch {
            let (dx, dy) = (pt[0] - m.x_m, pt[1] - m.y_m);
            let (xn, yn) = (c * dx + s * dy, -s * dx + c * dy);
            if xn < 0.1 {
                continue;
            }
            let un = (rig.centre_px[0] - f * (yn - half_b) / xn) / scale;
            let vn = (rig.centre_px[1] + f * (rig.height_m - pt[2]) / xn) / scale;
            let Some((inew, gu, gv)) = sample(new, un, vn) else { continue };
            // d(u, v) / d(x', y'), then d(x', y') / d(motion), at this level.
            let du = [f * (yn - half_b) / (xn * xn), -f / xn];
            let dv = -f * (rig.height_m - pt[2]) / (xn * xn);
            let dxy = [[-c, -s, yn], [s, -c, -xn]];
            let j3: [f64; 3] = std::array::from_fn(|k| {
                let du_k = du[0] * dxy[0][k] + du[1] * dxy[1][k];
                (gu * du_k + gv * dv * dxy[0][k]) / scale
            });
            rows.push((inew, io, j3));
        }
        if rows.len() < 9 {
            continue;
        }
        used += 1;
        // The patch's gain and offset: old ≈ gain * new + offset, by least squares.
        let n = rows.len() as f64;
        let (mn, mo) = (rows.iter().map(|r| r.0).sum::<f64>() / n, rows.iter().map(|r| r.1).sum::<f64>() / n);
        let var = rows.iter().map(|r| (r.0 - mn).powi(2)).sum::<f64>();
        let cov = rows.iter().map(|r| (r.0 - mn) * (r.1 - mo)).sum::<f64>();
        let gain = if var > 1e-9 { (cov / var).clamp(0.5, 2.0) } else { 1.0 };
        for &(inew, io, j3) in &rows {
            let res = gain * (inew - mn) - (io - mo);
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
    (h, g, used, if compared == 0 { f64::INFINITY } else { cost / compared as f64 })
}

/// The Huber weight of a difference `r` with knee `k`.
fn huber(r: f64, k: f64) -> f64 {
    if r.abs() <= k { 1.0 } else { k / r.abs() }
}

/// The image's bilinear interpolant at `(x, y)` (pixel centres at +0.5) and its gradient (per
/// pixel, the interpolant's own derivative: the same four pixels); `None` within a pixel of the
/// edge.
fn sample(img: &GrayBuf, x: f64, y: f64) -> Option<(f64, f64, f64)> {
    let (fx, fy) = (x - 0.5, y - 0.5);
    if !(fx >= 0.0 && fy >= 0.0 && fx < img.width as f64 - 1.0 && fy < img.height as f64 - 1.0) {
        return None;
    }
    let (ix, iy) = (fx as usize, fy as usize);
    let (ax, ay) = (fx - ix as f64, fy - iy as f64);
    let i = iy * img.width + ix;
    let at = |k: usize| f64::from(img.data[k]);
    let (p00, p10, p01, p11) = (at(i), at(i + 1), at(i + img.width), at(i + img.width + 1));
    let (top, bottom) = (p00 + ax * (p10 - p00), p01 + ax * (p11 - p01));
    let gu = (1.0 - ay) * (p10 - p00) + ay * (p11 - p01);
    Some((top + ay * (bottom - top), gu, bottom - top))
}
