//! The instruction-set paths of normalised correlation and Moravec against each other, in one
//! run: `cargo bench -p harvey-vision --bench kernels -- paths` (`-- paths moravec`: Moravec
//! only). Each path the CPU has (set per correlator or operator, so no `HARVEY_SIMD` is needed)
//! is timed in turn, several rounds interleaved so that a noisy machine slows them alike; a
//! round's figure is the median of its calls, the table's the median of the rounds, and each
//! ratio the median of the rounds' ratios to the portable path. Rows: the pruned search
//! (`Correlator::best`, the kernels bench's row), every placement's score
//! (`Correlator::correlate`, the cross-sum of all of them) and Moravec 5x5's corners.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::hint::black_box;

use harvey_vision::moravec::{Moravec, MoravecParams};
use harvey_vision::nc::{Correlator, Template};
use harvey_vision::simd::Path as SimdPath;
use harvey_vision::{Gray, GrayBuf, Rect};

use crate::{around, textured, time};

/// Interleaved rounds per row.
const ROUNDS: usize = 7;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Times `best` and `correlate` on each available path, full frame and a 48x48 window.
pub fn compare(img: &Gray<'_>, size: &str) {
    let tr = textured(img, 16);
    let t = GrayBuf::crop(img, tr).expect("template");
    let tmpl = Template::new(&t).expect("template");
    let scopes = [("full frame", img.full()), ("48x48 window", around(img, tr, 48))];
    let mut rows = Vec::new();
    for (scope, win) in scopes {
        for call in ["best", "correlate"] {
            rows.push((call, scope, win));
        }
    }
    table(size, &rows, |p, &(call, _, win)| run(p, call, img, win, &tmpl));
}

/// Times Moravec 5x5's corners (the kernels bench's rows) on each available path, full frame and
/// a 64x64 window.
pub fn compare_moravec(img: &Gray<'_>, size: &str) {
    let p = MoravecParams::default();
    let rows = [
        ("Moravec 5x5", "full frame", img.full()),
        ("Moravec 5x5", "64x64 window", around(img, textured(img, 16), 64)),
    ];
    table(size, &rows, |path, &(_, _, win)| {
        let mut m = Moravec::default();
        m.set_path(path);
        time(|| {
            black_box(m.corners(img, win, &p).expect("runs").len());
        })
    });
}

/// Prints one table row per `(call, scope, window)`, each path timed by `run` in interleaved
/// rounds, then each row's ratios of the portable path to the others.
fn table(size: &str, rows: &[(&str, &str, Rect)], run: impl Fn(SimdPath, &(&str, &str, Rect)) -> f64) {
    let paths = SimdPath::available();
    println!(
        "| call | image | scope | {} |",
        paths.iter().map(|p| format!("{p} µs")).collect::<Vec<_>>().join(" | ")
    );
    println!("|---|---|---|{}", "---:|".repeat(paths.len()));
    let mut ratios = Vec::new();
    for row in rows {
        let (call, scope, _) = *row;
        let mut us = vec![Vec::new(); paths.len()];
        for _ in 0..ROUNDS {
            for (i, &p) in paths.iter().enumerate() {
                us[i].push(run(p, row));
            }
        }
        let cells: Vec<String> = us.iter().map(|u| format!("{:.1}", median(u.clone()))).collect();
        println!("| {call} | {size} | {scope} | {} |", cells.join(" | "));
        for (i, &p) in paths.iter().enumerate().skip(1) {
            let r = median(us[0].iter().zip(&us[i]).map(|(a, b)| a / b).collect());
            ratios.push(format!("{call}, {scope}: portable / {p} = {r:.2}x"));
        }
    }
    for r in ratios {
        println!("{r}");
    }
}

/// Median µs of one call of `call` on `path` (a fresh correlator, warmed up by `time`).
fn run(path: SimdPath, call: &str, img: &Gray<'_>, win: Rect, tmpl: &Template) -> f64 {
    let mut c = Correlator::default();
    c.set_path(path);
    if call == "best" {
        time(|| {
            black_box(c.best(img, win, tmpl).expect("correlates"));
        })
    } else {
        time(|| {
            black_box(c.correlate(img, win, tmpl).expect("correlates").len());
        })
    }
}
