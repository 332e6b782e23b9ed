//! The instruction-set paths of normalised correlation, Moravec, the line finder and the region
//! segmenter against each other, in one run: `cargo bench -p harvey-vision --bench kernels --
//! paths` (`-- paths moravec`: Moravec only; `-- paths flf`: the line finder and segmenter). Each path the CPU has (set per correlator or operator, so no `HARVEY_SIMD` is needed)
//! is timed in turn, several rounds interleaved so that a noisy machine slows them alike; a
//! round's figure is the median of its calls, the table's the median of the rounds, and each
//! ratio the median of the rounds' ratios to the portable path. Rows: the pruned search
//! (`Correlator::best`, the kernels bench's row), every placement's score
//! (`Correlator::correlate`, the cross-sum of all of them), Moravec 5x5's corners, and the line
//! finder's and segmenter's rows of the kernels bench (same settings).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::hint::black_box;

use harvey_vision::flf::{Flf, FlfParams};
use harvey_vision::frs::{ClassRange, Frs};
use harvey_vision::moravec::{Moravec, MoravecParams};
use harvey_vision::nc::{Correlator, Template};
use harvey_vision::regions::Runs;
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

/// Times the line finder and the segmenter (the kernels bench's rows and settings) on each
/// available path, full frame and a 96x96 window, and the segmenter's run extraction and joining
/// alone on the full frame's class image.
pub fn compare_flf_frs(img: &Gray<'_>, size: &str) {
    let win = around(img, textured(img, 16), 96);
    let rows = [
        ("fast line finder", "full frame", img.full()),
        ("fast line finder", "96x96 window", win),
        ("fast region segmenter + stats", "full frame", img.full()),
        ("fast region segmenter + stats", "96x96 window", win),
        ("segmenter's runs alone (Runs::build)", "full frame", img.full()),
    ];
    let ranges = [
        ClassRange { lo: 0, hi: 70, class: 1 },
        ClassRange { lo: 71, hi: 170, class: 2 },
        ClassRange { lo: 171, hi: 255, class: 3 },
    ];
    let p = FlfParams::default();
    // The segmenter's class image of the frame, for the runs alone.
    let class = |v: u8| ranges.iter().find(|r| (r.lo..=r.hi).contains(&v)).map_or(0, |r| r.class);
    let labels: Vec<u8> = (0..img.height).flat_map(|y| img.row(y).iter().map(|&v| class(v))).collect();
    table(size, &rows, |path, &(kernel, _, win)| {
        if kernel.starts_with("segmenter's runs") {
            let mut runs = Runs::default();
            time(|| {
                runs.build(&labels, img.width, img.height, false, path);
                black_box(runs.regions);
            })
        } else if kernel == "fast line finder" {
            let mut f = Flf::default();
            f.set_path(path);
            time(|| {
                black_box(f.lines(img, win, &p).expect("runs").len());
            })
        } else {
            let mut f = Frs::default();
            f.set_path(path);
            time(|| {
                black_box(f.segment(img, win, &ranges, 20).expect("segments").len());
            })
        }
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
