//! The sweep's plot, `sweep.png`: the figure against the seed, one coloured series per condition,
//! a dot where the run succeeded and a cross where it failed, axes labelled with their units.
//! Drawn into an RGB image with the built-in font (`font.rs`), written as PNG.

use std::path::Path;

use image::{Rgb, RgbImage};

use super::figures::{Figure, Row};
use super::font;

const W: u32 = 960;
const H: u32 = 600;
const LEFT: u32 = 100;
const RIGHT: u32 = 200;
const TOP: u32 = 56;
const BOTTOM: u32 = 76;
const SCALE: u32 = 2;
const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
const INK: Rgb<u8> = Rgb([40, 40, 40]);
const GRID: Rgb<u8> = Rgb([225, 225, 225]);
/// Series colours (Tableau 10), in condition order; they repeat after ten.
const COLOURS: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

struct Canvas(RgbImage);

impl Canvas {
    fn put(&mut self, x: i64, y: i64, c: Rgb<u8>) {
        if (0..i64::from(W)).contains(&x) && (0..i64::from(H)).contains(&y) {
            self.0.put_pixel(x as u32, y as u32, c);
        }
    }

    /// A line `width` pixels thick.
    fn line(&mut self, (x0, y0): (f64, f64), (x1, y1): (f64, f64), width: i64, c: Rgb<u8>) {
        let n = (x1 - x0).abs().max((y1 - y0).abs()).ceil().max(1.0) as i64;
        for i in 0..=n {
            let t = i as f64 / n as f64;
            let (x, y) = ((x0 + (x1 - x0) * t).round() as i64, (y0 + (y1 - y0) * t).round() as i64);
            for d in 0..width {
                for e in 0..width {
                    self.put(x + d - width / 2, y + e - width / 2, c);
                }
            }
        }
    }

    fn dot(&mut self, (x, y): (f64, f64), r: f64, c: Rgb<u8>) {
        let ri = r.ceil() as i64;
        for dy in -ri..=ri {
            for dx in -ri..=ri {
                if ((dx * dx + dy * dy) as f64) <= r * r {
                    self.put(x.round() as i64 + dx, y.round() as i64 + dy, c);
                }
            }
        }
    }

    fn cross(&mut self, (x, y): (f64, f64), r: f64, c: Rgb<u8>) {
        self.line((x - r, y - r), (x + r, y + r), 3, c);
        self.line((x - r, y + r), (x + r, y - r), 3, c);
    }

    /// `s` with its top-left corner at `(x, y)`; `vertical` turns it to read upwards.
    fn text(&mut self, x: i64, y: i64, s: &str, vertical: bool, c: Rgb<u8>) {
        let sc = i64::from(SCALE);
        for (i, ch) in s.chars().enumerate() {
            let base = i as i64 * i64::from(font::ADVANCE) * sc;
            for col in 0..5 {
                for row in 0..font::HEIGHT {
                    if !font::pixel(ch, col, row) {
                        continue;
                    }
                    for (dx, dy) in (0..sc).flat_map(|a| (0..sc).map(move |b| (a, b))) {
                        let (u, v) = (base + i64::from(col) * sc + dx, i64::from(row) * sc + dy);
                        if vertical { self.put(x + v, y - u, c) } else { self.put(x + u, y + v, c) }
                    }
                }
            }
        }
    }
}

fn text_width(s: &str) -> i64 {
    (s.chars().count() as i64) * i64::from(font::ADVANCE * SCALE)
}

/// A tick step of 1, 2 or 5 times a power of ten giving some five ticks over `span`.
fn tick_step(span: f64) -> f64 {
    let raw = (span / 5.0).max(1e-9);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * p).find(|s| *s >= raw).unwrap_or(10.0 * p)
}

fn tick_label(v: f64, step: f64) -> String {
    let decimals = if step >= 1.0 { 0 } else { (-step.log10().floor()) as usize };
    format!("{v:.decimals$}")
}

/// Draws the plot of `rows` (conditions in `conditions` order) into `path`.
pub fn draw(
    path: &Path,
    title: &str,
    figure: Figure,
    conditions: &[String],
    rows: &[Row],
) -> anyhow::Result<()> {
    let mut c = Canvas(RgbImage::from_pixel(W, H, WHITE));
    let seeds: Vec<f64> = rows.iter().map(|r| r.seed as f64).collect();
    let (s_lo, s_hi) = seeds.iter().fold((f64::MAX, f64::MIN), |(a, b), &s| (a.min(s), b.max(s)));
    let (s_lo, s_hi) = if seeds.is_empty() { (0.0, 1.0) } else { (s_lo - 0.5, s_hi + 0.5) };
    let y_max = rows.iter().filter_map(|r| r.figure).fold(0.0, f64::max);
    let y_step = tick_step(if y_max > 0.0 { y_max * 1.1 } else { 1.0 });
    let y_hi = ((y_max * 1.05 / y_step).ceil() * y_step).max(y_step);
    let (x0, x1, y0, y1) = (LEFT as f64, (W - RIGHT) as f64, (H - BOTTOM) as f64, TOP as f64);
    let px = |s: f64| x0 + (s - s_lo) / (s_hi - s_lo) * (x1 - x0);
    let py = |v: f64| y0 - v / y_hi * (y0 - y1);
    // Grid, ticks and their labels.
    let mut v = 0.0;
    while v <= y_hi + y_step * 1e-6 {
        c.line((x0, py(v)), (x1, py(v)), 1, GRID);
        let l = tick_label(v, y_step);
        c.text(LEFT as i64 - 8 - text_width(&l), py(v) as i64 - 7, &l, false, INK);
        v += y_step;
    }
    let x_step = tick_step(s_hi - s_lo).max(1.0);
    let mut s = (s_lo / x_step).ceil() * x_step;
    while s <= s_hi {
        c.line((px(s), y0), (px(s), y0 + 6.0), 2, INK);
        let l = tick_label(s, x_step);
        c.text(px(s) as i64 - text_width(&l) / 2, y0 as i64 + 12, &l, false, INK);
        s += x_step;
    }
    c.line((x0, y0), (x1, y0), 2, INK);
    c.line((x0, y0), (x0, y1), 2, INK);
    c.text((x0 + x1) as i64 / 2 - text_width("seed") / 2, H as i64 - 36, "seed", false, INK);
    let label = figure.label();
    c.text(18, (y0 + y1) as i64 / 2 + text_width(label) / 2, label, true, INK);
    c.text(LEFT as i64, 18, title, false, INK);
    // One series per condition.
    for (i, name) in conditions.iter().enumerate() {
        let colour = Rgb(COLOURS[i % COLOURS.len()]);
        // Conditions side by side round each seed, so equal figures do not hide each other.
        let dodge = (i as f64 - (conditions.len() as f64 - 1.0) / 2.0) * (0.3 / conditions.len() as f64);
        let mut pts: Vec<(f64, f64, bool)> = rows
            .iter()
            .filter(|r| &r.condition == name)
            .filter_map(|r| r.figure.map(|f| (px(r.seed as f64 + dodge), py(f), r.succeeded())))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        for w in pts.windows(2) {
            c.line((w[0].0, w[0].1), (w[1].0, w[1].1), 2, colour);
        }
        for &(x, y, ok) in &pts {
            if ok { c.dot((x, y), 5.0, colour) } else { c.cross((x, y), 6.0, colour) }
        }
        let ly = TOP as f64 + 10.0 + 28.0 * i as f64;
        c.line((x1 + 20.0, ly), (x1 + 44.0, ly), 3, colour);
        c.dot((x1 + 32.0, ly), 5.0, colour);
        c.text(x1 as i64 + 54, ly as i64 - 7, name, false, INK);
    }
    let ly = TOP as f64 + 30.0 + 28.0 * conditions.len() as f64;
    c.dot((x1 + 32.0, ly), 5.0, INK);
    c.text(x1 as i64 + 54, ly as i64 - 7, "reached", false, INK);
    c.cross((x1 + 32.0, ly + 28.0), 6.0, INK);
    c.text(x1 as i64 + 54, ly as i64 + 21, "failed", false, INK);
    c.0.save_with_format(path, image::ImageFormat::Png)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_numbers() {
        assert_eq!(tick_step(10.0), 2.0);
        assert!((tick_step(0.33) - 0.1).abs() < 1e-12);
        assert_eq!(tick_step(3.0), 1.0);
        assert_eq!(tick_label(0.30000000000000004, 0.1), "0.3");
        assert_eq!(tick_label(4.0, 2.0), "4");
    }
}
