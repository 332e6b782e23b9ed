//! Coded pole recognition (004 §5.1.1): the bright ring regions of a frame grouped by column
//! into poles. A pole shows three rings: the top and bottom at known heights, so their spacing
//! in the image gives the pole's range, and the middle one at a height that is the pole's code,
//! read from where it sits between the other two (a ratio: no calibration of the range needed).

use harvey_vision::frs::Region;
use harvey_world::PoleField;

/// The poles among `rings` (bright regions) of an image `image_width` wide, each `[u, range_m,
/// code, v_top, v_bottom, 0]`. A column of other than three rings, whose middle ring is no code,
/// or cut by the image's side, is not a pole.
pub fn group<'a>(
    rings: &'a [Region],
    f: &'a PoleField,
    focal_px: f64,
    image_width: u32,
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
        Some([seed.centroid[0], range as f32, code as f32, top as f32, bottom as f32, 0.0])
    })
}
