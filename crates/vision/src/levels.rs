//! Grey-level statistics of a window (its histogram and percentiles), so that a threshold can
//! follow the image's own brightness (a dim or vignetted camera) instead of a fixed grey level.

use crate::image::{Gray, Rect};

/// How many pixels of `w` in `img` have each grey level.
pub fn histogram(img: &Gray<'_>, w: Rect) -> [u32; 256] {
    let mut h = [0u32; 256];
    for y in w.y0..w.y1 {
        for &p in &img.row(y)[w.x0..w.x1] {
            h[usize::from(p)] += 1;
        }
    }
    h
}

/// The lowest grey level at or below which at least the fraction `q` (0..=1) of the counted
/// pixels lie; 0 for an empty histogram.
pub fn percentile(h: &[u32; 256], q: f32) -> u8 {
    let n: u64 = h.iter().map(|&c| u64::from(c)).sum();
    if n == 0 {
        return 0;
    }
    let want = ((f64::from(q.clamp(0.0, 1.0)) * n as f64).ceil() as u64).max(1);
    let mut seen = 0u64;
    for (level, &c) in h.iter().enumerate() {
        seen += u64::from(c);
        if seen >= want {
            return level as u8;
        }
    }
    255
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::GrayBuf;

    #[test]
    fn percentiles_of_a_known_window() {
        // 100 pixels: levels 0..=99, one each.
        let img = GrayBuf::from_fn(10, 10, |x, y| (y * 10 + x) as u8);
        let h = histogram(&img.view(), img.view().full());
        assert_eq!(h.iter().sum::<u32>(), 100);
        assert_eq!(percentile(&h, 0.5), 49);
        assert_eq!(percentile(&h, 0.9), 89);
        assert_eq!(percentile(&h, 1.0), 99);
        assert_eq!(percentile(&h, 0.0), 0);
        // A sub-window counts only its own pixels.
        let h = histogram(&img.view(), Rect::new(0, 9, 10, 10));
        assert_eq!((percentile(&h, 0.0), percentile(&h, 1.0)), (90, 99));
        assert_eq!(percentile(&[0; 256], 0.5), 0);
    }
}
