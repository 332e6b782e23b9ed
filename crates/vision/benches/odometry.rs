//! Bench rows for the stereo visual odometry (003): one stop-to-stop step at 640x480 (the
//! first stop's features ranged, then the second stop's motion solved and its features topped
//! up), by matching then solving and by Lucas registration, against a plain reference of the
//! match-then-solve step (the reference Moravec operator, every placement of every correlation
//! in f64, the same solver) timed in the same run.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::hint::black_box;

use harvey_vision::odometry::reacquire::predicted_box;
use harvey_vision::odometry::solve::{Pair, solve};
use harvey_vision::odometry::{LucasParams, Motion, OdometryParams, Prior, Solver, VisualOdometry};
use harvey_vision::{Gray, GrayBuf, Rect};
use harvey_world::{Pose2, World};

use crate::reference::{moravec, nc_best};
use crate::{Row, frame_at, measure};

/// 003's rover: cameras 25 cm apart.
const BASELINE_M: f64 = 0.25;

fn params(world: &World, w: u32, h: u32, solver: Solver) -> OdometryParams {
    crate::odometry_params::params(world, w, h, BASELINE_M, solver)
}

pub fn bench_odometry(world: &World, rows: &mut Vec<Row>) {
    let (w, h) = (640u32, 480u32);
    let start = Pose2::new(1.0, 0.1, 0.02);
    let stop = start.arc(0.35, 0.03);
    let pair = |pose: Pose2| {
        (frame_at(world, w, h, pose.sideways(0.125)), frame_at(world, w, h, pose.sideways(-0.125)))
    };
    let ((l0, r0), (l1, r1)) = (pair(start), pair(stop));
    let truth = start.relative(&stop);
    let prior = Prior {
        motion: Motion {
            x_m: truth.x_m * 1.03,
            y_m: truth.y_m + 0.01,
            heading_rad: truth.heading_rad + 0.015,
        },
        sd: [0.03, 0.03, 0.035],
    };
    let views = [l0.view(), r0.view(), l1.view(), r1.view()];
    let lucas = Solver::Lucas(LucasParams { levels: 4, radius: 3, iterations: 5, huber: 3.0 });
    let plain = params(world, w, h, Solver::MatchThenSolve);
    for (kernel, solver) in [
        ("visual odometry, start + 1 step (match then solve)", Solver::MatchThenSolve),
        ("visual odometry, start + 1 step (Lucas)", lucas),
    ] {
        let mut vo = VisualOdometry::new(params(world, w, h, solver));
        let mut run = || {
            vo.start(&views[0], &views[1]).expect("starts");
            vo.step(&views[2], &views[3], &prior).expect("solves").solution.motion
        };
        let m = run();
        assert!((m.x_m - truth.x_m).hypot(m.y_m - truth.y_m) < 0.02, "{kernel}: {m:?} for {truth:?}");
        let reference = step(&views, &plain, &prior);
        assert!(
            (reference.x_m - truth.x_m).hypot(reference.y_m - truth.y_m) < 0.05,
            "reference: {reference:?}"
        );
        rows.push(measure(
            Row::new(kernel, "640x480", "full frame".to_owned(), views[0].full(), Rect::default()),
            || {
                black_box(run());
            },
            || {
                black_box(step(&views, &plain, &prior));
            },
        ));
    }
}

/// The plain step: corners of the first left image ranged by exhaustive band correlation,
/// each found again by exhaustive correlation in its predicted box and ranged again, the
/// motion solved; then the second left image's corners ranged (the top-up).
fn step(v: &[Gray<'_>; 4], p: &OdometryParams, prior: &Prior) -> Motion {
    let half = p.stereo.patch / 2;
    let old: Vec<([usize; 2], [f64; 3])> = ranged(&v[0], &v[1], p).collect();
    let mut pairs = Vec::new();
    for ([x, y], point) in old {
        let Some(window) = predicted_box(&p.rig, point, prior, p.box_sigmas, [v[2].width, v[2].height], half)
        else {
            continue;
        };
        let (bx, by, score) = nc_best(&v[2], window, &patch(&v[0], x, y, half));
        if score < f64::from(p.track_min_score) {
            continue;
        }
        let Some(new) = range(&v[2], &v[3], bx + half, by + half, p) else { continue };
        let cov = p.rig.covariance(point);
        pairs.push(Pair { old: point, new, old_cov: cov, new_cov: p.rig.covariance(new) });
    }
    let mut active = vec![true; pairs.len()];
    let m = solve(&pairs, &mut active, prior, p.edit_chi2, p.min_features).map_or(prior.motion, |s| s.motion);
    black_box(ranged(&v[2], &v[3], p).count());
    m
}

/// The reference corners of `left` with their stereo points.
fn ranged<'a>(
    left: &'a Gray<'a>,
    right: &'a Gray<'a>,
    p: &'a OdometryParams,
) -> impl Iterator<Item = ([usize; 2], [f64; 3])> + 'a {
    let c = p.stereo.moravec;
    let mut corners = moravec(left, left.full(), c.window, c.threshold, c.suppress_radius);
    corners.sort_by_key(|b| std::cmp::Reverse(b.2));
    corners.truncate(c.max_corners);
    corners.into_iter().filter_map(move |(x, y, _)| Some(([x, y], range(left, right, x, y, p)?)))
}

/// The point at pixel `(x, y)` of `left` by exhaustive correlation over its band.
fn range(left: &Gray<'_>, right: &Gray<'_>, x: usize, y: usize, p: &OdometryParams) -> Option<[f64; 3]> {
    let (half, band) = (p.stereo.patch / 2, p.stereo.band_rows);
    if x < half || y < half + band || y + half + band >= left.height || x + half >= left.width {
        return None;
    }
    let fb = p.stereo.focal_px * p.stereo.baseline_m;
    let (lo, hi) = (x as f32 - fb / p.stereo.near_m, x as f32 - fb / p.stereo.far_m);
    if hi < half as f32 {
        return None;
    }
    let x0 = lo.max(half as f32).floor() as usize - half;
    let x1 = (hi.ceil() as usize + half + 1).min(right.width);
    if x1 - x0 < 2 * half + 1 {
        return None;
    }
    let search = Rect::new(x0, y - half - band, x1, y + half + band + 1);
    let (bx, _, score) = nc_best(right, search, &patch(left, x, y, half));
    let disparity = x as f32 - (bx + half) as f32;
    (score >= f64::from(p.stereo.min_score))
        .then(|| p.rig.triangulate([x as f32 + 0.5, y as f32 + 0.5], disparity))?
}

fn patch(img: &Gray<'_>, x: usize, y: usize, half: usize) -> GrayBuf {
    GrayBuf::from_fn(2 * half + 1, 2 * half + 1, |i, j| img.at(x + i - half, y + j - half))
}
