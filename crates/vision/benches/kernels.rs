//! Per-kernel benchmark: each kernel at 640x480 and 256x256, over the full frame and in a window,
//! against a straightforward reference implementation measured in the same run, single thread,
//! on rendered hallway frames. Writes the frames (PGM) and the figures (TSV) to
//! `target/vision-bench/` for `scripts/bench-opencv`, which times OpenCV on the same images.
//!
//! It prints the CPU model, its SIMD features and the instruction-set path each row ran
//! (`HARVEY_SIMD=portable|avx2|avx512` lowers it, never past what the CPU has).
//!
//! `taskset -c 0 cargo bench -p harvey-vision --bench kernels`; with `-- paths`, only the
//! correlation and Moravec rows on every path the CPU has, against each other in one run
//! (`paths.rs`); with `-- odometry`, only the visual odometry's step (`odometry.rs`).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

mod geometry;
mod odometry;
#[path = "../tests/common/odometry_params.rs"]
mod odometry_params;
mod paths;
mod reference;
mod reference_geometry;
#[path = "../tests/common/sidewalk.rs"]
mod sidewalk;

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use harvey_msgs::Encoding;
use harvey_render::Renderer;
use harvey_vision::cues::{ActivityDetector, ActivityVote, brightest};
use harvey_vision::flf::{Flf, FlfParams};
use harvey_vision::frs::{ClassRange, Frs};
use harvey_vision::moravec::{Moravec, MoravecParams};
use harvey_vision::nc::{Correlator, Template};
use harvey_vision::pyramid::{Pyramid, coarse_to_fine};
use harvey_vision::simd::{self, Path as SimdPath};
use harvey_vision::{Gray, GrayBuf, Rect};

/// Median microseconds per call of `f`, over enough calls to fill about 0.3 s.
fn time(mut f: impl FnMut()) -> f64 {
    let start = Instant::now();
    f();
    let once = start.elapsed().as_secs_f64().max(1e-7);
    let reps = ((0.3 / once) as usize).clamp(5, 20_000);
    let mut samples: Vec<f64> = (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

struct Row {
    kernel: &'static str,
    size: String,
    scope: String,
    /// The window worked in, and (correlation) where the template was cut.
    window: Rect,
    template: Rect,
    harvey_us: f64,
    reference_us: f64,
    /// The instruction-set path Harvey's kernel ran.
    path: String,
}

impl Row {
    fn new(kernel: &'static str, size: &str, scope: String, window: Rect, template: Rect) -> Self {
        let path = path_of(kernel);
        Self {
            kernel,
            size: size.to_owned(),
            scope,
            window,
            template,
            harvey_us: 0.0,
            reference_us: 0.0,
            path,
        }
    }
}

/// The path a kernel runs: the dispatched one for correlation, Moravec, activity, the line
/// finder, the segmenter and what is built on them; the rest run the build's baseline code.
fn path_of(kernel: &str) -> String {
    let dispatched = [
        "normalised correlation",
        "Moravec",
        "coarse-to-fine",
        "stereo",
        "visual odometry",
        "depth from motion",
        "activity",
        "fast line finder",
        "fast region segmenter",
        "path following",
        "phototropic",
    ];
    if dispatched.iter().any(|k| kernel.starts_with(k)) {
        SimdPath::active().name().to_owned()
    } else {
        "baseline".to_owned()
    }
}

/// Times Harvey's kernel and the reference, in the same run.
fn measure(mut row: Row, harvey: impl FnMut(), reference: impl FnMut()) -> Row {
    (row.harvey_us, row.reference_us) = (time(harvey), time(reference));
    row
}

/// Looking down the hallway from its start: door jambs, tiles, signs.
fn frame(world: &harvey_world::World, w: u32, h: u32) -> GrayBuf {
    frame_at(world, w, h, geometry::POSE)
}

fn frame_at(world: &harvey_world::World, w: u32, h: u32, pose: harvey_world::Pose2) -> GrayBuf {
    let mut r = Renderer::new(world, w, h, Encoding::Mono8);
    let mut px = vec![0u8; r.frame_bytes()];
    r.render(world, pose, &mut px).expect("renders");
    GrayBuf { width: w as usize, height: h as usize, data: px }
}

fn write_pgm(path: &Path, img: &GrayBuf) {
    let mut bytes = format!("P5\n{} {}\n255\n", img.width, img.height).into_bytes();
    bytes.extend_from_slice(&img.data);
    std::fs::write(path, bytes).expect("writes the frame");
}

/// A window of `side` pixels centred in the frame.
#[allow(dead_code)]
fn centred(img: &Gray<'_>, side: usize) -> Rect {
    let (x0, y0) = ((img.width - side) / 2, (img.height - side) / 2);
    Rect::new(x0, y0, x0 + side, y0 + side)
}

/// The most textured `side`-pixel square on an 8-pixel grid: a place a template is unique.
fn textured(img: &Gray<'_>, side: usize) -> Rect {
    let variance = |x: usize, y: usize| {
        let px: Vec<f64> = (y..y + side)
            .flat_map(|r| (x..x + side).map(move |c| (c, r)))
            .map(|(c, r)| f64::from(img.at(c, r)))
            .collect();
        let mean = px.iter().sum::<f64>() / px.len() as f64;
        px.iter().map(|p| (p - mean).powi(2)).sum::<f64>()
    };
    let margin = 24;
    let (x, y) = (margin..img.width - side - margin)
        .step_by(8)
        .flat_map(|x| (margin..img.height - side - margin).step_by(8).map(move |y| (x, y)))
        .max_by(|a, b| variance(a.0, a.1).total_cmp(&variance(b.0, b.1)))
        .expect("a patch");
    Rect::new(x, y, x + side, y + side)
}

/// A `side`-pixel square centred on `r`, moved inside the image.
fn around(img: &Gray<'_>, r: Rect, side: usize) -> Rect {
    let centre = |a: usize, len: usize, max: usize| (a + len / 2).saturating_sub(side / 2).min(max - side);
    let (x0, y0) = (centre(r.x0, r.width(), img.width), centre(r.y0, r.height(), img.height));
    Rect::new(x0, y0, x0 + side, y0 + side)
}

fn bench_nc(img: &Gray<'_>, size: &str, rows: &mut Vec<Row>) {
    let tr = textured(img, 16);
    let t = GrayBuf::crop(img, tr).expect("template");
    let tmpl = Template::new(&t).expect("template");
    let mut c = Correlator::default();
    for (scope, win) in
        [("full frame".to_owned(), img.full()), ("48x48 window".to_owned(), around(img, tr, 48))]
    {
        let m = c.best(img, win, &tmpl).expect("correlates");
        assert_eq!((m.x, m.y), (tr.x0, tr.y0), "the template is found where it was cut");
        let kernel = "normalised correlation 16x16";
        rows.push(measure(
            Row::new(kernel, size, scope, win, tr),
            || {
                black_box(c.best(img, win, &tmpl).expect("correlates"));
            },
            || {
                black_box(reference::nc_best(img, win, &t));
            },
        ));
    }
}

fn bench_moravec(img: &Gray<'_>, size: &str, rows: &mut Vec<Row>) {
    let p = MoravecParams::default();
    let mut m = Moravec::default();
    let win = around(img, textured(img, 16), 64);
    for (scope, win) in [("full frame".to_owned(), img.full()), ("64x64 window".to_owned(), win)] {
        let ours = m.corners(img, win, &p).expect("runs").len();
        assert!(ours > 0, "no corner found in {scope}");
        let kernel = "Moravec 5x5";
        rows.push(measure(
            Row::new(kernel, size, scope, win, Rect::default()),
            || {
                black_box(m.corners(img, win, &p).expect("runs").len());
            },
            || {
                black_box(reference::moravec(img, win, p.window, p.threshold, p.suppress_radius));
            },
        ));
    }
}

fn bench_flf(img: &Gray<'_>, size: &str, rows: &mut Vec<Row>) {
    let p = FlfParams::default();
    let mut f = Flf::default();
    let win = around(img, textured(img, 16), 96);
    for (scope, win) in [("full frame".to_owned(), img.full()), ("96x96 window".to_owned(), win)] {
        assert!(!f.lines(img, win, &p).expect("runs").is_empty(), "no line in {scope}");
        let kernel = "fast line finder";
        rows.push(measure(
            Row::new(kernel, size, scope, win, Rect::default()),
            || {
                black_box(f.lines(img, win, &p).expect("runs").len());
            },
            || {
                black_box(reference::flf(img, win, p.buckets, p.min_gradient, f64::from(p.min_length)));
            },
        ));
    }
}

fn bench_frs(img: &Gray<'_>, size: &str, rows: &mut Vec<Row>) {
    // Three classes of grey: dark (door frames, skirting), mid (walls), bright (signs, lights).
    let ranges = [
        ClassRange { lo: 0, hi: 70, class: 1 },
        ClassRange { lo: 71, hi: 170, class: 2 },
        ClassRange { lo: 171, hi: 255, class: 3 },
    ];
    let plain: Vec<(u8, u8, u8)> = ranges.iter().map(|r| (r.lo, r.hi, r.class)).collect();
    let mut f = Frs::default();
    let win = around(img, textured(img, 16), 96);
    for (scope, win) in [("full frame".to_owned(), img.full()), ("96x96 window".to_owned(), win)] {
        let n = f.segment(img, win, &ranges, 20).expect("segments").len();
        assert_eq!(n, reference::frs(img, win, &plain, 20), "region count in {scope}");
        let kernel = "fast region segmenter + stats";
        rows.push(measure(
            Row::new(kernel, size, scope, win, Rect::default()),
            || {
                black_box(f.segment(img, win, &ranges, 20).expect("segments").len());
            },
            || {
                black_box(reference::frs(img, win, &plain, 20));
            },
        ));
    }
}

/// Coarse-to-fine (3 levels, pyramid built per frame) against the exhaustive search of the
/// same 32x32 template at full resolution.
fn bench_coarse_to_fine(img: &Gray<'_>, size: &str, rows: &mut Vec<Row>) {
    let tr = textured(img, 32);
    let t = GrayBuf::crop(img, tr).expect("template");
    let (mut pi, mut pt, mut c) = (Pyramid::default(), Pyramid::default(), Correlator::default());
    pt.build(&t.view(), 3).expect("template pyramid");
    let tmpl = Template::new(&t).expect("template");
    for (scope, win) in
        [("full frame".to_owned(), img.full()), ("96x96 window".to_owned(), around(img, tr, 96))]
    {
        // Over the whole frame for a full-frame search, over the window (widened to whole
        // coarsest pixels) for a search in it.
        let whole = win == img.full();
        let build = |pi: &mut Pyramid| {
            if whole { pi.build(img, 3) } else { pi.build_around(img, win, 3) }.expect("pyramid");
        };
        build(&mut pi);
        let m = coarse_to_fine(&pi, &pt, win, 2, &mut c).expect("found");
        assert_eq!((m.x, m.y), (tr.x0, tr.y0), "found where it was cut, {scope}");
        let kernel = "coarse-to-fine correlation 32x32 (vs exhaustive)";
        let mut exhaustive = Correlator::default();
        rows.push(measure(
            Row::new(kernel, size, scope, win, tr),
            || {
                build(&mut pi);
                black_box(coarse_to_fine(&pi, &pt, win, 2, &mut c).expect("found"));
            },
            || {
                black_box(exhaustive.best(img, win, &tmpl).expect("found"));
            },
        ));
    }
}

/// Activity detection (absolute differences, 4 frames) and phototropic perception.
fn bench_cues(img: &Gray<'_>, size: &str, rows: &mut Vec<Row>) {
    // A second view: the frame one pixel to the left, so that every edge moves.
    let moved = GrayBuf::from_fn(img.width, img.height, |x, y| img.at((x + 1).min(img.width - 1), y));
    let views = [*img, moved.view()];
    let win = around(img, textured(img, 16), 96);
    for (scope, win) in [("full frame".to_owned(), img.full()), ("96x96 window".to_owned(), win)] {
        let mut det = ActivityDetector::new(ActivityVote::Difference, 4);
        let mut kept = Vec::new();
        let mut k = 0usize;
        let mut k2 = 0usize;
        rows.push(measure(
            Row::new("activity detection, 4 frames", size, scope.clone(), win, Rect::default()),
            || {
                k += 1;
                black_box(det.push(&views[k % 2], win).expect("runs"));
            },
            || {
                k2 += 1;
                black_box(reference::activity(&mut kept, &views[k2 % 2], win, 4));
            },
        ));
        let mut frs = Frs::default();
        let ours = brightest(&mut frs, img, win, 20, 1).expect("runs").map_or(0, |r| r.area as usize);
        assert_eq!(ours, reference::brightest(img, win, 20), "brightest region in {scope}");
        rows.push(measure(
            Row::new("phototropic (brightest region)", size, scope, win, Rect::default()),
            || {
                black_box(brightest(&mut frs, img, win, 20, 1).expect("runs"));
            },
            || {
                black_box(reference::brightest(img, win, 20));
            },
        ));
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let world = harvey_world::World::load(&root.join("worlds/hallway.toml")).expect("world");
    let out = root.join("target/vision-bench");
    std::fs::create_dir_all(&out).expect("output folder");
    let (model, features, path) = (simd::cpu_model(), simd::cpu_features(), SimdPath::active());
    println!("CPU: {model}");
    println!("SIMD features: {features}");
    println!(
        "path: {path} (fastest here: {}; {}={:?})",
        SimdPath::best(),
        simd::ENV,
        std::env::var(simd::ENV).ok()
    );
    if std::env::args().any(|a| a == "paths") {
        let img = frame(&world, 640, 480);
        let only = |k: &str| std::env::args().any(|a| a == k);
        let all = !only("moravec") && !only("flf");
        if all {
            paths::compare(&img.view(), "640x480");
        }
        if all || only("moravec") {
            paths::compare_moravec(&img.view(), "640x480");
        }
        if all || only("flf") {
            paths::compare_flf_frs(&img.view(), "640x480");
        }
        return;
    }
    let mut rows = Vec::new();
    // `hough`: the constrained Hough's rows alone; `odometry`: the visual odometry's.
    let hough_only = std::env::args().any(|a| a == "hough");
    let odometry_only = std::env::args().any(|a| a == "odometry");
    if !hough_only {
        odometry::bench_odometry(&world, &mut rows);
    }
    for (w, h) in [(640u32, 480u32), (256, 256)].into_iter().filter(|_| !odometry_only) {
        let img = frame(&world, w, h);
        write_pgm(&out.join(format!("frame_{w}x{h}.pgm")), &img);
        let size = format!("{w}x{h}");
        if hough_only {
            geometry::bench_hough(&img, &size, &mut rows);
            continue;
        }
        bench_nc(&img.view(), &size, &mut rows);
        bench_moravec(&img.view(), &size, &mut rows);
        bench_flf(&img.view(), &size, &mut rows);
        bench_frs(&img.view(), &size, &mut rows);
        bench_coarse_to_fine(&img.view(), &size, &mut rows);
        bench_cues(&img.view(), &size, &mut rows);
        geometry::bench_stereo(&world, &img, &size, &mut rows);
        geometry::bench_depth(&world, &img, &size, &mut rows);
        geometry::bench_hough(&img, &size, &mut rows);
        geometry::bench_path(w as usize, h as usize, &size, &mut rows);
    }
    println!("| kernel | image | scope | path | harvey µs | reference µs | reference / harvey |");
    println!("|---|---|---|---|---:|---:|---:|");
    let mut tsv = format!("# cpu\t{model}\n# features\t{features}\n# path\t{path}\n");
    tsv += "kernel\tsize\tscope\twindow\ttemplate\tharvey_us\treference_us\tpath\n";
    for r in &rows {
        println!(
            "| {} | {} | {} | {} | {:.1} | {:.1} | {:.1}x |",
            r.kernel,
            r.size,
            r.scope,
            r.path,
            r.harvey_us,
            r.reference_us,
            r.reference_us / r.harvey_us
        );
        let rect = |r: Rect| format!("{},{},{},{}", r.x0, r.y0, r.x1, r.y1);
        tsv += &format!(
            "{}\t{}\t{}\t{}\t{}\t{:.3}\t{:.3}\t{}\n",
            r.kernel,
            r.size,
            r.scope,
            rect(r.window),
            rect(r.template),
            r.harvey_us,
            r.reference_us,
            r.path
        );
    }
    std::fs::write(out.join("harvey.tsv"), tsv).expect("writes the figures");
}
