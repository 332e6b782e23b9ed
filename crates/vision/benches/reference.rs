//! Straightforward reference implementations: the formulas as written, no reuse, no tricks. The
//! benchmark times each kernel against its reference in the same run.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use harvey_vision::{Gray, GrayBuf, Rect};

/// Normalised correlation (000 §5.4) placement by placement, each patch normalised by its sum.
pub fn nc_best(img: &Gray<'_>, win: Rect, t: &GrayBuf) -> (usize, usize, f64) {
    let st: f64 = t.data.iter().map(|&v| f64::from(v)).sum();
    let mut best = (0, 0, f64::MIN);
    for y in win.y0..=win.y1 - t.height {
        for x in win.x0..=win.x1 - t.width {
            let mut sp = 0.0;
            for r in 0..t.height {
                for c in 0..t.width {
                    sp += f64::from(img.at(x + c, y + r));
                }
            }
            let (mut pt, mut pp, mut tt) = (0.0, 0.0, 0.0);
            for r in 0..t.height {
                for c in 0..t.width {
                    let rp = f64::from(img.at(x + c, y + r)) / sp;
                    let rt = f64::from(t.data[r * t.width + c]) / st;
                    pt += rp * rt;
                    pp += rp * rp;
                    tt += rt * rt;
                }
            }
            let nc = 2.0 * pt / (pp + tt);
            if nc > best.2 {
                best = (x, y, nc);
            }
        }
    }
    best
}

/// The Moravec operator pixel by pixel: four shifted window sums, their minimum, then local
/// maxima by scanning every neighbourhood.
pub fn moravec(
    img: &Gray<'_>,
    win: Rect,
    k: usize,
    threshold: u32,
    radius: usize,
) -> Vec<(usize, usize, u32)> {
    let h = (k / 2) as isize;
    let (ww, wh) = (win.width(), win.height());
    let mut map = vec![0u32; ww * wh];
    let m = k / 2 + 1;
    for y in m..wh.saturating_sub(m) {
        for x in m..ww.saturating_sub(m) {
            let mut best = u32::MAX;
            for (dx, dy) in [(1isize, 0isize), (0, 1), (1, 1), (1, -1)] {
                let mut s = 0u32;
                for j in -h..=h {
                    for i in -h..=h {
                        let (px, py) = ((win.x0 + x) as isize + i, (win.y0 + y) as isize + j);
                        let d = i32::from(img.at(px as usize, py as usize))
                            - i32::from(img.at((px + dx) as usize, (py + dy) as usize));
                        s += (d * d) as u32;
                    }
                }
                best = best.min(s);
            }
            map[y * ww + x] = best;
        }
    }
    let mut out = Vec::new();
    for y in 0..wh {
        for x in 0..ww {
            let v = map[y * ww + x];
            if v < threshold {
                continue;
            }
            let mut peak = true;
            for j in y.saturating_sub(radius)..=(y + radius).min(wh - 1) {
                for i in x.saturating_sub(radius)..=(x + radius).min(ww - 1) {
                    if (i, j) != (x, y) && map[j * ww + i] > v {
                        peak = false;
                    }
                }
            }
            if peak {
                out.push((win.x0 + x, win.y0 + y, v));
            }
        }
    }
    out
}

/// The line finder the plain way: atan2 per pixel, pixel-by-pixel union-find over a label
/// image, moments accumulated pixel by pixel, one partition. Returns the number of lines.
pub fn flf(img: &Gray<'_>, win: Rect, buckets: u8, min_gradient: f32, min_length: f64) -> usize {
    let (w, h) = (win.width() - 1, win.height() - 1);
    let mut bucket = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let p = |i: usize, j: usize| f32::from(img.at(win.x0 + x + i, win.y0 + y + j));
            let gx = (p(1, 0) + p(1, 1) - p(0, 0) - p(0, 1)) / 2.0;
            let gy = (p(0, 1) + p(1, 1) - p(0, 0) - p(1, 0)) / 2.0;
            if (gx * gx + gy * gy).sqrt() >= min_gradient {
                let dir = gy.atan2(gx).to_degrees().rem_euclid(360.0);
                bucket[y * w + x] = (dir / (360.0 / f32::from(buckets))) as u8 % buckets + 1;
            }
        }
    }
    let mut parent = label_regions(&bucket, w, h);
    let mut sums = std::collections::HashMap::<usize, [f64; 6]>::new();
    for y in 0..h {
        for x in 0..w {
            if bucket[y * w + x] != 0 {
                let r = root(&mut parent, y * w + x);
                let s = sums.entry(r).or_default();
                let (fx, fy) = (x as f64, y as f64);
                for (k, v) in [1.0, fx, fy, fx * fx, fx * fy, fy * fy].into_iter().enumerate() {
                    s[k] += v;
                }
            }
        }
    }
    sums.values()
        .filter(|s| {
            let n = s[0];
            let (mx, my) = (s[1] / n, s[2] / n);
            let (cxx, cxy, cyy) = (s[3] / n - mx * mx, s[4] / n - mx * my, s[5] / n - my * my);
            let l1 = (cxx + cyy) / 2.0 + (((cxx - cyy) / 2.0).powi(2) + cxy * cxy).sqrt();
            (12.0 * l1 + 1.0).sqrt() >= min_length
        })
        .count()
}

/// Region segmentation the plain way: classify every pixel by searching the ranges,
/// pixel-by-pixel union-find (4 and diagonal neighbours), statistics accumulated pixel by
/// pixel in a map. Returns the number of regions of at least `min_area` pixels.
pub fn frs(img: &Gray<'_>, win: Rect, ranges: &[(u8, u8, u8)], min_area: usize) -> usize {
    let (w, h) = (win.width(), win.height());
    let mut class = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let v = img.at(win.x0 + x, win.y0 + y);
            class[y * w + x] = ranges.iter().find(|r| (r.0..=r.1).contains(&v)).map_or(0, |r| r.2);
        }
    }
    let mut parent = label_regions(&class, w, h);
    let mut stats = std::collections::HashMap::<usize, [f64; 5]>::new();
    for y in 0..h {
        for x in 0..w {
            if class[y * w + x] != 0 {
                let v = f64::from(img.at(win.x0 + x, win.y0 + y));
                let s = stats.entry(root(&mut parent, y * w + x)).or_default();
                for (k, a) in [1.0, x as f64, y as f64, v, v * v].into_iter().enumerate() {
                    s[k] += a;
                }
            }
        }
    }
    stats.values().filter(|s| s[0] >= min_area as f64).count()
}

/// Pixel-by-pixel union-find of equal non-zero classes (left and the three above, so
/// 8-connected); returns the parent forest for [`root`].
fn label_regions(class: &[u8], w: usize, h: usize) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..w * h).collect();
    for y in 0..h {
        for x in 0..w {
            let c = class[y * w + x];
            if c == 0 {
                continue;
            }
            for (dx, dy) in [(-1isize, 0isize), (-1, -1), (0, -1), (1, -1)] {
                let (nx, ny) = (x as isize + dx, y as isize + dy);
                if nx >= 0 && ny >= 0 && (nx as usize) < w && class[ny as usize * w + nx as usize] == c {
                    let (a, b) =
                        (root(&mut parent, y * w + x), root(&mut parent, ny as usize * w + nx as usize));
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    parent
}

/// The region (root pixel) of pixel `i`, halving paths on the way.
fn root(p: &mut [usize], mut i: usize) -> usize {
    while p[i] != i {
        p[i] = p[p[i]];
        i = p[i];
    }
    i
}

/// Activity detection the plain way: the last `depth` windows kept as fresh copies, the motion
/// plane recomputed from all pairs, its centroid. Returns the centroid.
pub fn activity(frames: &mut Vec<Vec<u8>>, img: &Gray<'_>, win: Rect, depth: usize) -> [f64; 2] {
    let mut copy = Vec::new();
    for y in win.y0..win.y1 {
        for x in win.x0..win.x1 {
            copy.push(img.at(x, y));
        }
    }
    frames.push(copy);
    if frames.len() > depth {
        frames.remove(0);
    }
    let w = win.width();
    let (mut sum, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for i in 0..frames[0].len() {
        let mut v = 0.0;
        for k in 1..frames.len() {
            v += f64::from(frames[k][i].abs_diff(frames[k - 1][i]));
        }
        sum += v;
        sx += v * ((i % w) as f64 + 0.5);
        sy += v * ((i / w) as f64 + 0.5);
    }
    [sx / sum.max(1e-9), sy / sum.max(1e-9)]
}

/// The brightest region the plain way: the window's maximum, every pixel within `margin` of it
/// marked, pixel-by-pixel union-find, the largest component. Returns its area.
pub fn brightest(img: &Gray<'_>, win: Rect, margin: u8) -> usize {
    let (w, h) = (win.width(), win.height());
    let peak = (win.y0..win.y1)
        .flat_map(|y| (win.x0..win.x1).map(move |x| (x, y)))
        .map(|(x, y)| img.at(x, y))
        .max()
        .unwrap_or(0);
    let class: Vec<u8> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| u8::from(img.at(win.x0 + x, win.y0 + y) >= peak.saturating_sub(margin)))
        .collect();
    let mut parent = label_regions(&class, w, h);
    let mut area = std::collections::HashMap::<usize, usize>::new();
    for (i, &c) in class.iter().enumerate() {
        if c != 0 {
            *area.entry(root(&mut parent, i)).or_default() += 1;
        }
    }
    area.values().copied().max().unwrap_or(0)
}
