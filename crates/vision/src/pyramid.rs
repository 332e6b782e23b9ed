//! Coarse-to-fine correlation (003): image and template halved level by level (2x2 means); the
//! template is found over the whole window at the coarsest level, then only re-sought within a
//! few pixels of the doubled position at each finer one.

use crate::image::{Gray, GrayBuf, Rect, VisionError};
use crate::nc::{Correlator, Match, Template};

/// An image and its halvings; buffers are kept between frames.
#[derive(Debug, Default, Clone)]
pub struct Pyramid {
    /// Level 0 is the image itself (copied), each next one half as wide and high.
    pub levels: Vec<GrayBuf>,
}

impl Pyramid {
    /// Builds `count` levels (1 = the image alone) from `img`.
    pub fn build(&mut self, img: &Gray<'_>, count: usize) -> Result<(), VisionError> {
        if count == 0 || img.width >> (count - 1) < 2 || img.height >> (count - 1) < 2 {
            return Err(VisionError::BadParameter(format!(
                "{count} levels of a {}x{} image",
                img.width, img.height
            )));
        }
        self.levels.resize_with(count, GrayBuf::default);
        let base = &mut self.levels[0];
        (base.width, base.height) = (img.width, img.height);
        base.data.clear();
        for y in 0..img.height {
            base.data.extend_from_slice(img.row(y));
        }
        for k in 1..count {
            let (done, rest) = self.levels.split_at_mut(k);
            let (src, dst) = (&done[k - 1], &mut rest[0]);
            (dst.width, dst.height) = (src.width / 2, src.height / 2);
            dst.data.clear();
            for y in 0..dst.height {
                let (r0, r1) = (&src.data[2 * y * src.width..], &src.data[(2 * y + 1) * src.width..]);
                dst.data.extend((0..dst.width).map(|x| {
                    let s = u16::from(r0[2 * x])
                        + u16::from(r0[2 * x + 1])
                        + u16::from(r1[2 * x])
                        + u16::from(r1[2 * x + 1]);
                    ((s + 2) / 4) as u8
                }));
            }
        }
        Ok(())
    }
}

/// Finds `template` (level 0 of its pyramid) in `window` of `image` from the coarsest level
/// down, searching `reach` pixels round the doubled position at each finer level.
pub fn coarse_to_fine(
    image: &Pyramid,
    template: &Pyramid,
    window: Rect,
    reach: usize,
    correlator: &mut Correlator,
) -> Result<Match, VisionError> {
    let levels = image.levels.len().min(template.levels.len());
    let top = levels.checked_sub(1).ok_or(VisionError::EmptyTemplate)?;
    let scaled = |r: Rect, k: usize| Rect::new(r.x0 >> k, r.y0 >> k, r.x1 >> k, r.y1 >> k);
    let mut found: Option<(usize, usize)> = None;
    let mut best = None;
    for k in (0..=top).rev() {
        let (img, tpl) = (image.levels[k].view(), &template.levels[k]);
        let t = Template::new(tpl)?;
        let win = match found {
            None => scaled(window, k),
            Some((x, y)) => {
                // The doubled position, give or take `reach`, inside the window at this level.
                let lim = scaled(window, k);
                let (x0, y0) =
                    ((2 * x).saturating_sub(reach).max(lim.x0), (2 * y).saturating_sub(reach).max(lim.y0));
                let x1 = (2 * x + reach + tpl.width).min(lim.x1);
                let y1 = (2 * y + reach + tpl.height).min(lim.y1);
                Rect::new(x0, y0, x1, y1)
            }
        };
        let m = correlator.best(&img, win, &t)?;
        found = Some((m.x, m.y));
        best = Some(m);
    }
    best.ok_or(VisionError::EmptyTemplate)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Value noise: random levels on a `cell` grid, interpolated bilinearly.
    fn noise(x: usize, y: usize, cell: usize, seed: usize) -> f32 {
        let h = |i: usize, j: usize| {
            ((i.wrapping_mul(73_856_093) ^ j.wrapping_mul(19_349_663) ^ seed).wrapping_mul(2_654_435_761)
                >> 16)
                % 256
        };
        let (i, j) = (x / cell, y / cell);
        let (fx, fy) = ((x % cell) as f32 / cell as f32, (y % cell) as f32 / cell as f32);
        let l = |a: usize, b: usize| h(a, b) as f32;
        let top = l(i, j) * (1.0 - fx) + l(i + 1, j) * fx;
        let bottom = l(i, j + 1) * (1.0 - fx) + l(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    fn scene(w: usize, h: usize) -> GrayBuf {
        // Coarse blobs (unique at every level) over finer texture.
        GrayBuf::from_fn(w, h, |x, y| {
            (0.5 * noise(x, y, 24, 1) + 0.3 * noise(x, y, 8, 2) + 0.2 * noise(x, y, 3, 3)) as u8
        })
    }

    #[test]
    fn coarse_to_fine_finds_what_the_exhaustive_search_finds() {
        let img = scene(640, 480);
        let (mut pi, mut pt, mut c) = (Pyramid::default(), Pyramid::default(), Correlator::default());
        pi.build(&img.view(), 3).expect("pyramid");
        for (x, y) in [(100, 80), (400, 300), (517, 41)] {
            let tpl = GrayBuf::crop(&img.view(), Rect::new(x, y, x + 32, y + 32)).expect("crop");
            pt.build(&tpl.view(), 3).expect("pyramid");
            let fast = coarse_to_fine(&pi, &pt, img.view().full(), 2, &mut c).expect("found");
            let full =
                c.best(&img.view(), img.view().full(), &Template::new(&tpl).expect("t")).expect("found");
            assert_eq!((fast.x, fast.y), (full.x, full.y));
            assert_eq!((fast.x, fast.y), (x, y));
        }
        assert!(pi.build(&img.view(), 10).is_err(), "too many levels");
    }
}
