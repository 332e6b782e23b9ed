//! The Hough peaks verified (004 §4.1.2's coverage check): round each peak the reference point
//! is tried over the scales between the hypotheses' (widened a tenth either way), coarsely
//! (placements a cell apart, every other pixel a model unit), then fitted by least squares to
//! the lines that cover it, and scored by how much of the model the image lines cover. The
//! hypotheses alone are too coarse: five of them spread over the believed distance +-1.22 m lie
//! 16-34 px a model unit apart at 2.5-3.5 m, while a line must lie within 3 px of the model to
//! cover it.

use super::{DockMatch, DockModel, Hypothesis};
use crate::flf::Line;

/// Across distance (px) within which a line covers a model segment.
const ACROSS_PX: f32 = 3.0;
/// The scales tried reach this far beyond the hypotheses' range (a share of it).
const WIDEN: f32 = 0.1;
/// Lines of like orientation to a model segment: within this many degrees (as the votes).
const LIKE_DEG: f32 = 10.0;
/// How far (cells) from a peak the model's reference point is looked for.
const SEARCH_CELLS: usize = 2;

/// The best fit of the model round `peak`: the placement, scale and rotation covering the most.
/// `near` is scratch space for the lines that can touch the model.
pub(super) fn verify(
    lines: &[Line],
    model: &DockModel,
    hypotheses: &[Hypothesis],
    peak: [f32; 2],
    cell: f32,
    near: &mut Vec<Line>,
) -> Option<DockMatch> {
    let lo = hypotheses.iter().map(|h| h.scale).fold(f32::INFINITY, f32::min) * (1.0 - WIDEN);
    let hi = hypotheses.iter().map(|h| h.scale).fold(0.0, f32::max) * (1.0 + WIDEN);
    let model_len: f32 = model.segments.iter().map(|s| (s[1][0] - s[0][0]).hypot(s[1][1] - s[0][1])).sum();
    let reach = model
        .segments
        .iter()
        .flatten()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0f32, f32::max)
        .mul_add(hi, (SEARCH_CELLS + 1) as f32 * cell + ACROSS_PX);
    near.clear();
    near.extend(lines.iter().copied().filter(|l| {
        let (u0, u1) = (l.from[0].min(l.to[0]), l.from[0].max(l.to[0]));
        let (v0, v1) = (l.from[1].min(l.to[1]), l.from[1].max(l.to[1]));
        u1 >= peak[0] - reach && u0 <= peak[0] + reach && v1 >= peak[1] - reach && v0 <= peak[1] + reach
    }));
    if near.is_empty() || !lo.is_finite() || lo <= 0.0 {
        return None;
    }
    near.sort_unstable_by(|a, b| a.orientation_deg.total_cmp(&b.orientation_deg));
    let steps = ((hi - lo).max(0.0).floor() as usize) + 1;
    let mut best: Option<(f32, DockMatch)> = None;
    for (k, hyp) in hypotheses.iter().enumerate() {
        if hypotheses[..k].iter().any(|p| p.rotation == hyp.rotation) {
            continue;
        }
        let cov = |at: [f32; 2], scale: f32| coverage(near, model, scale, hyp.rotation, at);
        // Coarse: placements a cell apart round the peak (a peak's votes spread over a few
        // cells when the true scale lies between the hypotheses'), every other scale; the
        // model is then within 3 px of where it fits best.
        let mut coarse = (0.0f32, peak, lo);
        let r = SEARCH_CELLS as i32;
        for (i, j) in (-r..=r).flat_map(|i| (-r..=r).map(move |j| (i, j))) {
            let at = [peak[0] + i as f32 * cell, peak[1] + j as f32 * cell];
            for scale in (0..steps).step_by(2).map(|k| lo + k as f32) {
                let c = cov(at, scale);
                if c > coarse.0 {
                    coarse = (c, at, scale);
                }
            }
        }
        // Fine: the placement and scale that put the model's segments on the lines covering
        // them, by least squares (twice: the lines covering are taken again at the first fit).
        let (mut top, mut at, mut scale) = coarse;
        for _ in 0..2 {
            let Some((a, s)) = fit(near, model, scale, hyp.rotation, at) else { break };
            let c = cov(a, s);
            if c < top {
                break;
            }
            (top, at, scale) = (c, a, s);
        }
        if top > 0.0 && best.as_ref().is_none_or(|(c, _)| top > *c) {
            let m = DockMatch { at, certainty: (top / model_len).min(1.0), scale, rotation: hyp.rotation };
            best = Some((top, m));
        }
    }
    best.map(|(_, m)| m)
}

/// The reference point and scale that best put the model's segments on the lines covering them
/// under (`at`, `scale`) (`lines` sorted by orientation): each such line's ends pulled across onto its segment's line, weighted
/// by its overlap, solved for (u, v, scale). `None` where the lines do not fix all three (one
/// direction of segments seen alone).
fn fit(
    lines: &[Line],
    model: &DockModel,
    scale: f32,
    rotation: f32,
    at: [f32; 2],
) -> Option<([f32; 2], f32)> {
    let (c, s) = (f64::from(rotation.cos()), f64::from(rotation.sin()));
    let (at64, sc) = ([f64::from(at[0]), f64::from(at[1])], f64::from(scale));
    let (mut a, mut b) = ([[0.0f64; 3]; 3], [0.0f64; 3]);
    for seg in &model.segments {
        let rot = |p: [f32; 2]| {
            [f64::from(p[0]) * c - f64::from(p[1]) * s, f64::from(p[0]) * s + f64::from(p[1]) * c]
        };
        let (m0, m1) = (rot(seg[0]), rot(seg[1]));
        let (p0, p1) =
            ([at64[0] + sc * m0[0], at64[1] + sc * m0[1]], [at64[0] + sc * m1[0], at64[1] + sc * m1[1]]);
        let len = (p1[0] - p0[0]).hypot(p1[1] - p0[1]);
        if len <= 0.0 {
            continue;
        }
        let (ux, uy) = ((p1[0] - p0[0]) / len, (p1[1] - p0[1]) / len);
        let n = [uy, -ux];
        let across =
            |p: [f32; 2]| ((f64::from(p[0]) - p0[0]) * n[0] + (f64::from(p[1]) - p0[1]) * n[1]).abs();
        let along = |p: [f32; 2]| (f64::from(p[0]) - p0[0]) * ux + (f64::from(p[1]) - p0[1]) * uy;
        // Every point of the segment's line has n . p = n . at + scale * (n . m0).
        let row = [n[0], n[1], n[0] * m0[0] + n[1] * m0[1]];
        for l in like(lines, ux, uy) {
            if across(l.from) > f64::from(ACROSS_PX) || across(l.to) > f64::from(ACROSS_PX) {
                continue;
            }
            let (t0, t1) = (along(l.from).min(along(l.to)), along(l.from).max(along(l.to)));
            let w = (t1.min(len) - t0.max(0.0)).max(0.0);
            if w <= 0.0 {
                continue;
            }
            for p in [l.from, l.to] {
                let y = n[0] * f64::from(p[0]) + n[1] * f64::from(p[1]);
                for (i, ri) in row.iter().enumerate() {
                    b[i] += w * ri * y;
                    for (j, rj) in row.iter().enumerate() {
                        a[i][j] += w * ri * rj;
                    }
                }
            }
        }
    }
    let x = solve3(a, b)?;
    let fitted = ([x[0] as f32, x[1] as f32], x[2] as f32);
    (fitted.1 > 0.0 && (fitted.1 - scale).abs() < 0.25 * scale).then_some(fitted)
}

/// `a x = b` for a symmetric 3x3 `a` by Cramer's rule; `None` when `a` is (nearly) singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    let size = a[0][0] * a[1][1] * a[2][2];
    if !d.is_finite() || d.abs() <= 1e-9 * size || size <= 0.0 {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        *xk = det(m) / d;
    }
    Some(x)
}

/// The lines of `sorted` (by orientation) within `LIKE_DEG` of direction `dx, dy`.
fn like(sorted: &[Line], dx: f64, dy: f64) -> impl Iterator<Item = &Line> {
    let deg = dy.atan2(dx).to_degrees().rem_euclid(180.0) as f32;
    let range = |lo: f32, hi: f32| {
        let from = sorted.partition_point(|l| l.orientation_deg < lo);
        let to = sorted.partition_point(|l| l.orientation_deg <= hi);
        sorted.get(from..to.max(from)).unwrap_or(&[])
    };
    let (lo, hi) = (deg - LIKE_DEG, deg + LIKE_DEG);
    let main = range(lo.max(0.0), hi.min(180.0));
    // Directions wrap at 180 degrees.
    let wrapped = if lo < 0.0 {
        range(lo + 180.0, 180.0)
    } else if hi > 180.0 {
        range(0.0, hi - 180.0)
    } else {
        &[]
    };
    main.iter().chain(wrapped)
}

/// Model length (in model units) that image lines cover when the model is placed at `at` with
/// `scale` pixels a unit and image rotation `rotation`: lines of like orientation (`lines`
/// sorted by it) within `ACROSS_PX` of a model segment at both ends, by their overlap along it.
pub(super) fn coverage(lines: &[Line], model: &DockModel, scale: f32, rotation: f32, at: [f32; 2]) -> f32 {
    let (c, s) = (rotation.cos(), rotation.sin());
    let map = |p: [f32; 2]| [at[0] + scale * (p[0] * c - p[1] * s), at[1] + scale * (p[0] * s + p[1] * c)];
    let mut covered = 0.0;
    for seg in &model.segments {
        let (a, b) = (map(seg[0]), map(seg[1]));
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        if len <= 0.0 {
            continue;
        }
        let (ux, uy) = ((b[0] - a[0]) / len, (b[1] - a[1]) / len);
        let along = |p: [f32; 2]| (p[0] - a[0]) * ux + (p[1] - a[1]) * uy;
        let across = |p: [f32; 2]| ((p[0] - a[0]) * uy - (p[1] - a[1]) * ux).abs();
        let mut here = 0.0;
        for l in like(lines, f64::from(ux), f64::from(uy)) {
            if across(l.from) > ACROSS_PX || across(l.to) > ACROSS_PX {
                continue;
            }
            let (t0, t1) = (along(l.from).min(along(l.to)), along(l.from).max(along(l.to)));
            here += (t1.min(len) - t0.max(0.0)).max(0.0);
        }
        covered += here.min(len) / scale;
    }
    covered
}
