//! The step-line search (`step_line.rs`) on drawn images: a faint straight step in noise and a
//! checker texture, over seeds and angles, found where no single column shows it above its noise,
//! and noise alone (and the opposite step) scoring far below it.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_geometry::Rng;
use harvey_vision::path::ImageLine;
use harvey_vision::step_line::{HALF_ROWS, Profiles};

use harvey_vision::{GrayBuf, Rect};

const W: usize = 320;
const H: usize = 160;
/// The harsh day's gravel against dry grass: a step of 18 grey levels under noise of sd 8, on a
/// checker of +-5 in 10 px cells.
const STEP: f32 = 18.0;
const NOISE: f64 = 8.0;
const CHECKER: f32 = 5.0;

/// A frame with the step across `line` (`step` lighter below it; 0: none), noise and checker.
fn frame(line: &ImageLine, step: f32, seed: u64) -> GrayBuf {
    let mut rng = Rng::new(seed);
    let noise: Vec<f64> = (0..W * H).map(|_| rng.normal(0.0, NOISE)).collect();
    GrayBuf::from_fn(W, H, |x, y| {
        let below = (y as f32 + 0.5) > line.y_at(x as f32 + 0.5);
        let checker = if (x / 10 + y / 10) % 2 == 0 { CHECKER } else { -CHECKER };
        let v = 90.0 + if below { step } else { 0.0 } + checker + noise[y * W + x] as f32;
        v.round().clamp(0.0, 255.0) as u8
    })
}

/// The step's deviation for one column from noise alone: a difference of two means of
/// `HALF_ROWS` noisy rows.
fn noise_step_sd() -> f32 {
    (NOISE * (2.0 / HALF_ROWS as f64).sqrt()) as f32
}

#[test]
fn a_faint_step_is_found_along_its_line_over_seeds_and_angles() {
    let mut p = Profiles::default();
    let mut scratch = Vec::new();
    let mut buf: Vec<f32> = Vec::new();
    let (mut worst_row, mut worst_angle, mut least_z, mut columns_shown) = (0.0f32, 0.0f32, f32::MAX, 0.0f32);
    let mut n = 0;
    for (k, deg) in [-55.0f32, -35.0, -12.0, 0.0, 20.0, 48.0].into_iter().enumerate() {
        for seed in 1..=8u64 {
            let truth = ImageLine { point: [W as f32 / 2.0, H as f32 / 2.0 + 7.3], angle: deg.to_radians() };
            let img = frame(&truth, STEP, seed * 31 + k as u64);
            p.measure(&img.view(), Rect::new(0, 0, W, H), 2, false);
            let found = p.best_line((-1.3, 1.3), &mut scratch).expect("a line");
            let mid = found.line.point[0];
            worst_row = worst_row.max((found.line.y_at(mid) - truth.y_at(mid)).abs());
            worst_angle = worst_angle.max((found.line.angle - truth.angle).abs());
            least_z = least_z.min(found.z(p.spread(&mut buf)));
            // How many columns show the step as their own strongest above four deviations.
            let shown = (0..p.columns.len())
                .filter(|&c| {
                    let v = truth.y_at(p.columns[c] as f32);
                    let best = (p.top..p.top + p.rows)
                        .max_by(|&a, &b| p.at(c, a).unwrap().total_cmp(&p.at(c, b).unwrap()));
                    best.is_some_and(|r| {
                        (r as f32 - v).abs() <= 2.0 && p.at(c, r).unwrap() >= 4.0 * noise_step_sd()
                    })
                })
                .count();
            columns_shown += shown as f32 / p.columns.len() as f32;
            n += 1;
        }
    }
    let shown = columns_shown / n as f32;
    println!(
        "worst row {worst_row:.2} px, worst angle {:.2} deg, least z {least_z:.1}, columns showing it alone {:.0} %",
        worst_angle.to_degrees(),
        100.0 * shown
    );
    assert!(worst_row <= 1.5, "worst row {worst_row}");
    assert!(worst_angle.to_degrees() <= 1.0, "worst angle {}", worst_angle.to_degrees());
    assert!(least_z >= 12.0, "least z {least_z}");
    // The step is below what a column shows alone: the search is what finds it.
    assert!(shown <= 0.25, "{:.0} % of the columns showed the step alone", 100.0 * shown);
}

#[test]
fn noise_texture_and_the_opposite_step_score_far_below_the_edge() {
    let mut p = Profiles::default();
    let mut scratch = Vec::new();
    let mut buf: Vec<f32> = Vec::new();
    let (mut noise_z, mut opposite_z) = (0.0f32, 0.0f32);
    for seed in 1..=12u64 {
        let truth = ImageLine { point: [W as f32 / 2.0, 70.0], angle: (-30.0f32).to_radians() };
        let img = frame(&truth, 0.0, seed);
        p.measure(&img.view(), Rect::new(0, 0, W, H), 2, false);
        noise_z = noise_z.max(p.best_line((-1.3, 1.3), &mut scratch).expect("a line").z(p.spread(&mut buf)));
        // The step lighter below, looked for as darker below.
        let img = frame(&truth, STEP, seed);
        p.measure(&img.view(), Rect::new(0, 0, W, H), 2, true);
        let opposite = p.best_line((-1.3, 1.3), &mut scratch).expect("a line");
        opposite_z = opposite_z.max(opposite.z(p.spread(&mut buf)));
    }
    println!("best z of noise alone {noise_z:.1}, of the opposite sign {opposite_z:.1}");
    assert!(noise_z <= 7.5, "noise alone scored {noise_z}");
    assert!(opposite_z <= 7.5, "the opposite step scored {opposite_z}");
}

#[test]
fn a_window_too_small_or_steep_angles_give_nothing() {
    let mut p = Profiles::default();
    let mut scratch = Vec::new();
    let img = frame(&ImageLine { point: [0.0, 50.0], angle: 0.0 }, STEP, 1);
    p.measure(&img.view(), Rect::new(10, 10, 24, 100), 2, false);
    assert_eq!(p.columns.len(), 7);
    assert!(p.best_line((-1.0, 1.0), &mut scratch).is_none(), "7 columns are too few");
    p.measure(&img.view(), Rect::new(0, 40, W, 45), 2, false);
    assert_eq!(p.rows, 0);
    assert!(p.best_line((-1.0, 1.0), &mut scratch).is_none(), "no rows");
    p.measure(&img.view(), Rect::new(0, 0, W, H), 2, false);
    assert!(p.best_line((1.4, 1.5), &mut scratch).is_none(), "steeper than the columns can find");
    let level = p.best_line((-0.01, 0.01), &mut scratch).expect("level");
    assert!((level.line.y_at(160.0) - 50.0).abs() <= 1.0, "{level:?}");
}

#[test]
fn a_line_set_aside_gives_the_next_best() {
    let mut p = Profiles::default();
    let mut scratch = Vec::new();
    // Two steps: a strong one along row 50 and a fainter one along a slope lower down.
    let strong = ImageLine { point: [0.0, 50.0], angle: 0.0 };
    let faint = ImageLine { point: [W as f32 / 2.0, 110.0], angle: 0.3 };
    let a = frame(&strong, 80.0, 7);
    let b = frame(&faint, 20.0, 8);
    let img = GrayBuf::from_fn(W, H, |x, y| {
        let (va, vb) = (f32::from(a.view().at(x, y)), f32::from(b.view().at(x, y)));
        ((va + vb) / 2.0 + if (y as f32 + 0.5) > faint.y_at(x as f32 + 0.5) { 10.0 } else { 0.0 }) as u8
    });
    p.measure(&img.view(), Rect::new(0, 0, W, H), 2, false);
    let first = p.best_line((-1.3, 1.3), &mut scratch).expect("the strong line");
    assert!((first.line.y_at(160.0) - 50.0).abs() <= 1.5 && first.line.angle.abs() < 0.01, "{first:?}");
    p.suppress(&first.line, 3.0);
    let second = p.best_line((-1.3, 1.3), &mut scratch).expect("the faint line");
    assert!((second.line.y_at(160.0) - 110.0).abs() <= 1.5, "{second:?}");
    assert!((second.line.angle - 0.3).abs() < 0.02, "{second:?}");
    assert_eq!(p.sum_along(&first.line, 1).0, 0.0, "set aside");
}
