//! Bench rows for the kernels that work on lines, corners or frame pairs: stereo, depth from
//! motion, the constrained Hough transform and path following, each against its reference.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::hint::black_box;

use harvey_vision::depth::{DepthFromMotion, DepthParams};
use harvey_vision::flf::{Flf, FlfParams, Line};
use harvey_vision::hough::{DockModel, HoughScratch, Hypothesis, find_dock};
use harvey_vision::moravec::MoravecParams;
use harvey_vision::path::{ImageLine, PathParams, PathTracker};
use harvey_vision::stereo::{Stereo, StereoParams};
use harvey_vision::{GrayBuf, Rect};
use harvey_world::{Pose2, World};

use crate::sidewalk::sidewalk;
use crate::{Row, around, frame_at, measure, reference, reference_geometry, textured};

/// Where the bench frames are taken from (the kernels bench's own frame).
pub const POSE: Pose2 = Pose2::new(0.5, -0.3, 0.05);

const CORNERS: MoravecParams =
    MoravecParams { window: 5, threshold: 3000, suppress_radius: 4, max_corners: 120 };

fn scopes(img: &GrayBuf, side: usize) -> [(String, Rect); 2] {
    let v = img.view();
    [
        ("full frame".to_owned(), v.full()),
        (format!("{side}x{side} window"), around(&v, textured(&v, 16), side)),
    ]
}

pub fn bench_stereo(world: &World, left: &GrayBuf, size: &str, rows: &mut Vec<Row>) {
    let (c, s) = (POSE.heading_rad.cos(), POSE.heading_rad.sin());
    let right_pose = Pose2 { x_m: POSE.x_m + 0.3 * s, y_m: POSE.y_m - 0.3 * c, ..POSE };
    let right = frame_at(world, left.width as u32, left.height as u32, right_pose);
    let p = StereoParams {
        focal_px: world.camera.focal_for(left.width as u32) as f32,
        baseline_m: 0.3,
        band_rows: 1,
        near_m: 1.5,
        far_m: 12.0,
        patch: 9,
        min_score: 0.98,
        min_margin: 0.0,
        moravec: CORNERS,
    };
    let fb = p.focal_px * p.baseline_m;
    let mut st = Stereo::default();
    let (l, r) = (left.view(), right.view());
    for (scope, win) in scopes(left, 128) {
        let n = st.match_points(&l, &r, win, &p).expect("matches").len();
        assert!(n > 0, "no stereo match in {scope}");
        rows.push(measure(
            Row::new("stereo (Moravec + band correlation)", size, scope, win, Rect::default()),
            || {
                black_box(st.match_points(&l, &r, win, &p).expect("matches").len());
            },
            || {
                let c = (CORNERS.threshold, CORNERS.suppress_radius, CORNERS.max_corners);
                black_box(reference_geometry::stereo(
                    &l,
                    &r,
                    win,
                    (fb / p.far_m, fb / p.near_m),
                    1,
                    4,
                    0.98,
                    c,
                ));
            },
        ));
    }
}

pub fn bench_depth(world: &World, first: &GrayBuf, size: &str, rows: &mut Vec<Row>) {
    let (w, h) = (first.width as u32, first.height as u32);
    let step = 0.15;
    let next = frame_at(
        world,
        w,
        h,
        Pose2 {
            x_m: POSE.x_m + step * POSE.heading_rad.cos(),
            y_m: POSE.y_m + step * POSE.heading_rad.sin(),
            ..POSE
        },
    );
    let p = DepthParams {
        foe: [w as f32 / 2.0, h as f32 / 2.0],
        focal_px: world.camera.focal_for(w) as f32,
        patch: 11,
        startup_reach_px: 40.0,
        min_depth_m: 0.0,
        update_reach_px: 4.0,
        noise_px: 0.3,
        min_score: 0.97,
        recut_score: 0.995,
        register_reach_px: 0.0,
        moravec: CORNERS,
    };
    let mut dfm = DepthFromMotion::new(p);
    let (a, b) = (first.view(), next.view());
    for (scope, win) in scopes(first, 128) {
        let mut run = || {
            dfm.start(&a, win, 0.0).expect("starts");
            dfm.update(&b, step).expect("updates")
        };
        assert!(run() > 0, "no point tracked in {scope}");
        rows.push(measure(
            Row::new("depth from motion (start + 1 update)", size, scope, win, Rect::default()),
            || {
                black_box(run());
            },
            || {
                let c = (CORNERS.threshold, CORNERS.suppress_radius, CORNERS.max_corners);
                black_box(reference_geometry::depth_first_update(
                    &a,
                    &b,
                    win,
                    p.foe,
                    p.startup_reach_px,
                    5,
                    c,
                ));
            },
        ));
    }
}

/// The frame's lines in each scope (the Hough and path rows time what comes after the finder).
fn lines(img: &GrayBuf, side: usize) -> Vec<(String, Rect, Vec<Line>)> {
    let mut flf = Flf::default();
    scopes(img, side)
        .into_iter()
        .map(|(scope, win)| {
            let l = flf.lines(&img.view(), win, &FlfParams::default()).expect("lines").to_vec();
            (scope, win, l)
        })
        .collect()
}

pub fn bench_hough(img: &GrayBuf, size: &str, rows: &mut Vec<Row>) {
    let hyps: Vec<Hypothesis> =
        [30.0, 35.0, 40.0, 45.0, 50.0].iter().map(|&scale| Hypothesis { scale, rotation: 0.0 }).collect();
    let model = DockModel::frame_with_post();
    let dims = [img.width, img.height];
    let mut votes = HoughScratch::default();
    for (scope, win, lines) in lines(img, 192) {
        rows.push(measure(
            Row::new(
                "constrained Hough (5 hypotheses)",
                size,
                format!("{scope}, {} lines", lines.len()),
                win,
                Rect::default(),
            ),
            || {
                black_box(find_dock(&lines, &model, &hyps, dims, 4.0, &mut votes));
            },
            || {
                black_box(reference_geometry::hough(&lines, &model, &hyps, dims));
            },
        ));
    }
}

/// Path following on a sidewalk drawn in perspective (the one of the path tests), with the
/// prediction 10 px and 3 degrees off its edges.
pub fn bench_path(w: usize, h: usize, size: &str, rows: &mut Vec<Row>) {
    let (vp, xl, xr) = ([w as f32 / 2.0, h as f32 * 0.42], w as f32 * 0.23, w as f32 * 0.77);
    let img = &sidewalk([w, h], vp, xl, xr, false);
    let v = img.view();
    let full = v.full();
    let lower = Rect::new(0, h / 2, w, h);
    let mut flf = Flf::default();
    let p = FlfParams { min_length: 15.0, min_gradient: 10.0, ..FlfParams::default() };
    let all = flf.lines(&v, full, &p).expect("lines").to_vec();
    let off =
        |x: f32| ImageLine { point: [x + 10.0, h as f32], angle: (h as f32 - vp[1]).atan2(x - vp[0]) + 0.05 };
    let (left, right) = (off(xl), off(xr));
    let params = PathParams { max_distance_px: 15.0, max_angle: 0.1, min_confidence: 100.0 };
    let (horizon, bottom) = (vp[1], h as f32 - 1.0);
    for (scope, win) in [("full frame".to_owned(), full), ("lower half".to_owned(), lower)] {
        let mut tracker = PathTracker::new(left, right, horizon, bottom, params);
        let fit = tracker.update(flf.lines(&v, win, &p).expect("lines")).expect("the path is found");
        assert!((fit.vanishing[0] - vp[0]).abs() < 3.0, "{scope}: {fit:?}");
        rows.push(measure(
            Row::new("path following (FLF + grouping)", size, scope, win, Rect::default()),
            || {
                let mut t = PathTracker::new(left, right, horizon, bottom, params);
                black_box(t.update(flf.lines(&v, win, &p).expect("lines")));
            },
            || {
                // The reference line finder; the grouping, linear in the lines, is Harvey's.
                black_box(reference::flf(&v, win, p.buckets, p.min_gradient, f64::from(p.min_length)));
                let mut t = PathTracker::new(left, right, horizon, bottom, params);
                black_box(t.update(&all));
            },
        ));
    }
}
