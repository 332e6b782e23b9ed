//! Every instruction-set path this CPU has (`harvey_vision::simd::Path::available`) gives the
//! same results, bit for bit, as the portable one: correlation scores and matches, Moravec
//! interest maps and corners, coarse-to-fine matches, the fast line finder's lines (its gradient
//! pass and run extraction) and the region segmenter's regions (its runs), on random images of odd widths (1, 15,
//! 17, 641 px: no path may read past a row end or lose the last pixels) and on rendered frames;
//! and the pruned search of `Correlator::best` gives the exhaustive search's match, bit for bit,
//! with templates cut from the frame searched (best score 1) and from another frame (below 1).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_msgs::Encoding;
use harvey_render::Renderer;
use harvey_vision::flf::{Flf, FlfParams};
use harvey_vision::frs::{ClassRange, Frs};
use harvey_vision::moravec::{Moravec, MoravecParams};
use harvey_vision::nc::{Correlator, Match, Template};
use harvey_vision::pyramid::{Pyramid, coarse_to_fine};
use harvey_vision::simd::Path;
use harvey_vision::{Gray, GrayBuf, Rect};
use harvey_world::{Pose2, World};

/// A hashed image: every byte value, no structure.
fn random(w: usize, h: usize, seed: u64) -> GrayBuf {
    GrayBuf::from_fn(w, h, |x, y| {
        let mut z = seed ^ ((y * w + x) as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        (z >> 56) as u8
    })
}

fn rendered(w: u32, h: u32, pose: Pose2) -> GrayBuf {
    let world: World =
        harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads");
    let mut r = Renderer::new(&world, w, h, Encoding::Mono8);
    let mut px = vec![0u8; r.frame_bytes()];
    r.render(&world, pose, &mut px).expect("renders");
    GrayBuf { width: w as usize, height: h as usize, data: px }
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Scores of `t` (cut from `img` at `at`) in `win`, on each path, all equal to the portable ones.
fn correlation_agrees(img: &Gray<'_>, win: Rect, at: Rect) {
    // A template that happens to be all black is refused on every path alike.
    let Ok(t) = Template::new(&GrayBuf::crop(img, at).expect("crop")) else { return };
    let mut want = Correlator::default();
    want.set_path(Path::Portable);
    let all = want.correlate(img, win, &t).expect("correlates").to_vec();
    let scores = bits(&all);
    let best = want.best(img, win, &t).expect("best");
    // The pruned search gives the exhaustive one's match, bit for bit.
    let (nx, ny) = want.placements();
    let exhaustive = exhaustive_best(&all, nx, ny, win, (t.width, t.height));
    assert_eq!(format!("{best:?}"), format!("{exhaustive:?}"), "pruned vs exhaustive: {win}, {at}");
    for path in Path::available() {
        let mut c = Correlator::default();
        c.set_path(path);
        assert_eq!(c.path(), path);
        assert_eq!(bits(c.correlate(img, win, &t).expect("correlates")), scores, "{path}: {win}, {at}");
        let got = c.best(img, win, &t).expect("best");
        assert_eq!(format!("{got:?}"), format!("{best:?}"), "{path}: {win}, {at}");
    }
}

/// The best placement as the definition has it: the first of the highest scores of every
/// placement, refined by parabolas through its neighbours.
fn exhaustive_best(scores: &[f32], nx: usize, ny: usize, win: Rect, (tw, th): (usize, usize)) -> Match {
    let (i, score) =
        scores.iter().copied().enumerate().fold((0, f32::MIN), |b, (i, s)| if s > b.1 { (i, s) } else { b });
    let (px, py) = (i % nx, i / nx);
    let at = |x: usize, y: usize| scores[y * nx + x];
    let vertex = |a: f32, b: f32, c: f32| {
        let d = a - 2.0 * b + c;
        if d < 0.0 { (0.5 * (a - c) / d).clamp(-0.5, 0.5) } else { 0.0 }
    };
    let dx = if px > 0 && px + 1 < nx { vertex(at(px - 1, py), score, at(px + 1, py)) } else { 0.0 };
    let dy = if py > 0 && py + 1 < ny { vertex(at(px, py - 1), score, at(px, py + 1)) } else { 0.0 };
    let (x, y) = (win.x0 + px, win.y0 + py);
    let centre = [x as f32 + tw as f32 / 2.0 + dx, y as f32 + th as f32 / 2.0 + dy];
    Match { x, y, centre, score }
}

/// A template cut from `from` at `at`, searched for in `img` (so that the best score is below 1
/// and the pruned search has to find it among near misses), on each path.
fn correlation_agrees_across(img: &Gray<'_>, from: &Gray<'_>, win: Rect, at: Rect) {
    let Ok(t) = Template::new(&GrayBuf::crop(from, at).expect("crop")) else { return };
    let mut want = Correlator::default();
    want.set_path(Path::Portable);
    let all = want.correlate(img, win, &t).expect("correlates").to_vec();
    let (nx, ny) = want.placements();
    let exhaustive = format!("{:?}", exhaustive_best(&all, nx, ny, win, (t.width, t.height)));
    for path in Path::available() {
        let mut c = Correlator::default();
        c.set_path(path);
        assert_eq!(format!("{:?}", c.best(img, win, &t).expect("best")), exhaustive, "{path}: {win}, {at}");
    }
}

/// Interest map and corners in `win` on each path, all equal to the portable ones.
fn moravec_agrees(img: &Gray<'_>, win: Rect) {
    for (window, r) in [(3, 1), (5, 3), (7, 2), (9, 5)] {
        let p = MoravecParams { window, threshold: 1, suppress_radius: r, max_corners: 100_000 };
        let mut want = Moravec::default();
        want.set_path(Path::Portable);
        let map = want.interest_map(img, win, &p).expect("runs").to_vec();
        let corners = want.corners(img, win, &p).expect("runs").to_vec();
        for path in Path::available() {
            let mut m = Moravec::default();
            m.set_path(path);
            assert_eq!(m.interest_map(img, win, &p).expect("runs"), &map[..], "{path}: {win}, k {window}");
            assert_eq!(m.corners(img, win, &p).expect("runs"), &corners[..], "{path}: {win}, k {window}");
        }
    }
}

/// The line finder's lines in `win` on each path (overlapping partitions and one, adaptive and
/// fixed floors), all equal to the portable ones; how many lines they find.
fn flf_agrees(img: &Gray<'_>, win: Rect) -> usize {
    let base = FlfParams { min_length: 2.0, max_dispersion: 10.0, ..FlfParams::default() };
    let mut found = 0;
    for p in [
        base,
        FlfParams { overlap: false, buckets: 5, offset_deg: 10.0, ..base },
        FlfParams { noise_factor: 0.0, min_gradient: 2.0, ..base },
    ] {
        let mut want = Flf::default();
        want.set_path(Path::Portable);
        let lines = format!("{:?}", want.lines(img, win, &p).expect("runs"));
        for path in Path::available() {
            let mut f = Flf::default();
            f.set_path(path);
            assert_eq!(f.path(), path);
            assert_eq!(format!("{:?}", f.lines(img, win, &p).expect("runs")), lines, "{path}: {win}, {p:?}");
        }
        found += want.lines(img, win, &p).expect("runs").len();
    }
    found
}

/// The segmenter's regions in `win` on each path (three classes and a gap, then one wide
/// class), all equal to the portable ones; how many regions they find.
fn frs_agrees(img: &Gray<'_>, win: Rect) -> usize {
    let three = [
        ClassRange { lo: 0, hi: 70, class: 1 },
        ClassRange { lo: 71, hi: 150, class: 2 },
        ClassRange { lo: 171, hi: 255, class: 15 },
    ];
    let one = [ClassRange { lo: 20, hi: 240, class: 7 }];
    let mut found = 0;
    for ranges in [&three[..], &one[..]] {
        let mut want = Frs::default();
        want.set_path(Path::Portable);
        let regions = format!("{:?}", want.segment(img, win, ranges, 1).expect("segments"));
        for path in Path::available() {
            let mut f = Frs::default();
            f.set_path(path);
            let got = format!("{:?}", f.segment(img, win, ranges, 1).expect("segments"));
            assert_eq!(got, regions, "{path}: {win}, {ranges:?}");
        }
        found += want.segment(img, win, ranges, 1).expect("segments").len();
    }
    found
}

#[test]
fn random_images_of_odd_widths_agree_on_every_path() {
    // The large templates span several of the portable kernel's chunks of columns and groups of
    // rows (`cross/portable.rs`), the last of each partial.
    for (w, h) in [(1, 9), (15, 13), (17, 21), (641, 23), (33, 40), (71, 66)] {
        let img = random(w, h, (w * 1000 + h) as u64);
        let v = img.view();
        for (tw, th) in [(1, 1), (1, 7), (3, 2), (7, 5), (15, 4), (16, 16), (17, 3), (33, 41), (50, 22)] {
            if tw > w || th > h {
                continue;
            }
            let at = Rect::new(w - tw, h - th, w, h);
            correlation_agrees(&v, v.full(), at);
            let other = random(w, h, (w * 7 + h) as u64);
            correlation_agrees_across(&v, &other.view(), v.full(), at);
            if w > tw + 2 && h > th + 1 {
                correlation_agrees(&v, Rect::new(1, 1, w - 1, h), at.clamp_to(1, 1));
            }
        }
        moravec_agrees(&v, v.full());
        assert!(flf_agrees(&v, v.full()) > 0 || w < 33, "{w}x{h}: no line");
        assert!(frs_agrees(&v, v.full()) > 0, "{w}x{h}: no region");
        if w > 4 && h > 4 {
            moravec_agrees(&v, Rect::new(1, 2, w - 2, h - 1));
            flf_agrees(&v, Rect::new(1, 2, w - 2, h - 1));
            frs_agrees(&v, Rect::new(1, 2, w - 2, h - 1));
        }
    }
}

#[test]
fn rendered_frames_agree_on_every_path() {
    let poses = [Pose2::new(0.5, -0.3, 0.05), Pose2::new(3.0, 0.2, 0.3)];
    for (w, h) in [(640, 480), (641, 97), (17, 15)] {
        for pose in poses {
            let img = rendered(w, h, pose);
            let v = img.view();
            let side = 16.min(w as usize).min(h as usize);
            let (cx, cy) = (w as usize / 2 - side / 2, h as usize / 2 - side / 2);
            let at = Rect::new(cx, cy, cx + side, cy + side);
            correlation_agrees(&v, v.full(), at);
            moravec_agrees(&v, v.full());
            let (lines, regions) = (flf_agrees(&v, v.full()), frs_agrees(&v, v.full()));
            assert!(w < 600 || (lines > 10 && regions > 0), "{w}x{h}: {lines} lines, {regions} regions");
        }
        // Templates from the other pose's frame: best scores below 1, found among near misses.
        let (a, b) = (rendered(w, h, poses[0]), rendered(w, h, poses[1]));
        let side = 16.min(w as usize).min(h as usize);
        for (x, y) in [(0, 0), (w as usize / 3, h as usize / 2), (w as usize - side, h as usize - side)] {
            let (x, y) = (x.min(w as usize - side), y.min(h as usize - side));
            let at = Rect::new(x, y, x + side, y + side);
            correlation_agrees_across(&b.view(), &a.view(), b.view().full(), at);
            correlation_agrees_across(&a.view(), &b.view(), a.view().full(), at);
        }
    }
    // Coarse-to-fine over whole-frame and windowed pyramids, on each path.
    let img = rendered(640, 480, poses[0]);
    let v = img.view();
    let at = Rect::new(300, 200, 332, 232);
    let mut pt = Pyramid::default();
    pt.build(&GrayBuf::crop(&v, at).expect("crop").view(), 3).expect("pyramid");
    let win = Rect::new(270, 170, 366, 266);
    let (mut whole, mut part) = (Pyramid::default(), Pyramid::default());
    whole.build(&v, 3).expect("pyramid");
    part.build_around(&v, win, 3).expect("pyramid");
    let mut c = Correlator::default();
    c.set_path(Path::Portable);
    let want = format!("{:?}", coarse_to_fine(&whole, &pt, win, 2, &mut c));
    for path in Path::available() {
        c.set_path(path);
        assert_eq!(format!("{:?}", coarse_to_fine(&whole, &pt, win, 2, &mut c)), want, "{path}");
        assert_eq!(format!("{:?}", coarse_to_fine(&part, &pt, win, 2, &mut c)), want, "{path}, windowed");
    }
}

/// Moving a rectangle inside `[x0, ..) x [y0, ..)`, keeping its size.
trait ClampTo {
    fn clamp_to(self, x0: usize, y0: usize) -> Rect;
}

impl ClampTo for Rect {
    fn clamp_to(self, x0: usize, y0: usize) -> Rect {
        let (dx, dy) = (x0.saturating_sub(self.x0), y0.saturating_sub(self.y0));
        Rect::new(self.x0 + dx, self.y0 + dy, self.x1 + dx, self.y1 + dy)
    }
}

#[test]
fn neon_is_the_path_an_aarch64_cpu_takes() {
    // Every aarch64 CPU has NEON, so the comparisons above run it against the portable path.
    if cfg!(target_arch = "aarch64") {
        assert!(Path::available().contains(&Path::Neon));
        assert_eq!(Path::best(), Path::Neon);
    } else {
        assert!(!Path::available().contains(&Path::Neon));
    }
}
