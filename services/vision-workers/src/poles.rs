//! Coded pole recognition (004 §5.1.1): the bright ring regions of a frame grouped by column
//! into poles. A pole shows three rings: the top and bottom at known heights, so their spacing
//! in the image gives the pole's range, and the middle one at a height that is the pole's code,
//! read from where it sits between the other two (a ratio: no calibration of the range needed).

use harvey_vision::frs::Region;
use harvey_vision::levels::{histogram, percentile};
use harvey_vision::noise::noise_sigma;
use harvey_vision::{Gray, Rect};
use harvey_world::PoleField;

/// The contrast a request that names none gets (the poles mission sends its own,
/// `[mission.poles] ring_contrast`).
pub const RING_CONTRAST: f32 = 1.4;

/// The window's "bright background": its 90th percentile (ring tape never covers a tenth of a
/// window; walls, floor and pole bodies do).
const BACKGROUND_QUANTILE: f32 = 0.9;
/// A ring's threshold stands at least this many noise sigmas above the bright background, so
/// that noise alone (a pixel passes with odds of about 3 in 10 million) never makes a ring.
const NOISE_SIGMAS: f32 = 5.0;

/// The grey level from which a pixel of `w` counts as ring tape: `contrast` times the window's
/// bright background, and at least [`NOISE_SIGMAS`] of its own noise above it (004 §5.1.1's
/// tape is retro-reflective, brighter than anything else in view, whatever the illumination; a
/// fixed grey level misses it under a dim light or towards a vignetted corner). At most 255.
pub fn ring_threshold(img: &Gray<'_>, w: Rect, contrast: f32) -> u8 {
    let background = f32::from(percentile(&histogram(img, w), BACKGROUND_QUANTILE));
    let floor = background + NOISE_SIGMAS * noise_sigma(img, w);
    (contrast * background).max(floor).ceil().clamp(1.0, 255.0) as u8
}

/// The poles among `rings` (bright regions) of an image `image_width` wide, each `[u, range_m,
/// code, v_top, v_bottom, 0]`. A column of other than three rings, whose middle ring is no code,
/// whose rings are more than twice as wide as the pole at its range (and 2 px), further than
/// `farthest_m` (the world's diagonal), or cut by the image's side, is not a pole.
pub fn group<'a>(
    rings: &'a [Region],
    f: &'a PoleField,
    focal_px: f64,
    image_width: u32,
    farthest_m: f64,
) -> impl Iterator<Item = [f32; 6]> + 'a {
    rings.iter().enumerate().filter_map(move |(i, seed)| {
        if seed.bbox[0] == 0 || seed.bbox[2] + 1 >= image_width {
            return None;
        }
        let width = (seed.bbox[2] - seed.bbox[0] + 1) as f32;
        let column = |r: &Region| (r.centroid[0] - seed.centroid[0]).abs() <= (0.6 * width).max(3.0);
        // Each column once: from its first ring in the list.
        if rings[..i].iter().any(column) {
            return None;
        }
        let mut vs = [0f32; 3];
        let mut n = 0;
        for r in rings.iter().filter(|r| column(r)) {
            if n == 3 {
                return None;
            }
            vs[n] = r.centroid[1];
            n += 1;
        }
        if n != 3 {
            return None;
        }
        vs.sort_by(f32::total_cmp);
        let [top, mid, bottom] = vs.map(f64::from);
        let span = bottom - top;
        if span < 6.0 {
            return None;
        }
        let height = f.bottom_m + (bottom - mid) / span * (f.top_m - f.bottom_m);
        let code = f.code_at(height)?;
        let range = focal_px * (f.top_m - f.bottom_m) / span;
        // Nothing in the world is further away than `farthest_m` (ring fragments at a vignetted
        // edge, close together, read as a pole tens of metres off).
        if range > farthest_m {
            return None;
        }
        // The rings are as wide as the pole at that range: a column of bright patches much
        // wider than a pole so far away (a lit floor tile, a paper on a box) is not one.
        let expected = focal_px * f.side_m / range;
        if f64::from(width) > 2.0 * expected + 2.0 {
            return None;
        }
        Some([seed.centroid[0], range as f32, code as f32, top as f32, bottom as f32, 0.0])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_vision::GrayBuf;

    /// Walls at `wall`, three rings of tape at `tape` in a column, and a hashed noise of +-`n`.
    fn scene(wall: u8, tape: u8, n: u8) -> GrayBuf {
        GrayBuf::from_fn(120, 90, |x, y| {
            let ring = (50..58).contains(&x) && [20, 40, 70].iter().any(|r| (*r..r + 3).contains(&y));
            let z = ((x * 7919 + y * 104_729) % 251) as i32 % (2 * i32::from(n) + 1) - i32::from(n);
            (i32::from(if ring { tape } else { wall }) + z).clamp(0, 255) as u8
        })
    }

    /// Three rings `width` px wide in column 300, at rows `rows`.
    fn column(width: u32, rows: [f32; 3]) -> Vec<Region> {
        rows.iter()
            .map(|&v| Region {
                class: 1,
                area: 2 * width,
                bbox: [300, v as u32, 300 + width - 1, v as u32 + 1],
                centroid: [300.0 + (width - 1) as f32 / 2.0, v],
                mean: 220.0,
                sd: 0.0,
            })
            .collect()
    }

    #[test]
    fn a_column_of_rings_too_far_or_too_wide_for_a_pole_is_none() {
        let w = harvey_world::load_str(include_str!("../../../worlds/arena.toml"), "arena").expect("loads");
        let f = w.poles.as_ref().expect("the arena has poles");
        let focal = w.camera.focal_px;
        // A pole 4 m away: top and bottom rings f (top - bottom) / 4 apart, code 3 between.
        let span = focal * (f.top_m - f.bottom_m) / 4.0;
        let mid = f.code_height_m(3);
        let at = |h: f64| (240.0 - focal * (h - 1.0) / 4.0) as f32;
        let rows = [at(f.top_m), at(mid), at(f.bottom_m)];
        assert!((f64::from(rows[2] - rows[0]) - span).abs() < 1.0);
        // The pole is 0.15 m wide: 21 px at 4 m.
        let poles: Vec<_> = group(&column(21, rows), f, focal, 640, 18.0).collect();
        assert_eq!(poles.len(), 1);
        assert!((poles[0][1] - 4.0).abs() < 0.05 && poles[0][2] == 3.0, "{poles:?}");
        // The same rings 60 px wide are no pole 4 m off; nor is one further than the world.
        assert_eq!(group(&column(60, rows), f, focal, 640, 18.0).count(), 0);
        assert_eq!(group(&column(21, rows), f, focal, 640, 3.5).count(), 0);
    }

    #[test]
    fn the_threshold_follows_the_light_and_sits_between_walls_and_tape() {
        for (wall, tape) in [(110, 220), (85, 170), (60, 120)] {
            let img = scene(wall, tape, 4);
            let t = ring_threshold(&img.view(), img.view().full(), 1.4);
            assert!(t > wall + 4 && t < tape - 4, "wall {wall}, tape {tape}: threshold {t}");
        }
        // With no tape in view the threshold stays above every wall pixel.
        let img = scene(100, 100, 4);
        let t = ring_threshold(&img.view(), img.view().full(), 1.4);
        assert!(t > 104, "{t}");
    }
}
