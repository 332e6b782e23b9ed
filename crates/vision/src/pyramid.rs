//! Coarse-to-fine correlation (003): image and template halved level by level (2x2 means); the
//! template is found over the whole window at the coarsest level, then only re-sought within a
//! few pixels of the doubled position at each finer one. For a search in a window the pyramid
//! can be built over the window alone ([`Pyramid::build_around`]), with the same results.

use crate::image::{Gray, GrayBuf, Rect, VisionError};
use crate::nc::{Correlator, Match, Template};

/// An image and its halvings; buffers are kept between frames.
#[derive(Debug, Default, Clone)]
pub struct Pyramid {
    /// Level 0 is the image itself (copied), each next one half as wide and high.
    pub levels: Vec<GrayBuf>,
    /// Built over part of a frame: where level 0 starts in it, and the frame's size.
    crop: Option<Crop>,
}

/// The part of a frame a pyramid was built over.
#[derive(Debug, Default, Clone, Copy)]
struct Crop {
    origin: (usize, usize),
    frame: (usize, usize),
}

impl Pyramid {
    /// Builds `count` levels (1 = the image alone) from `img`.
    pub fn build(&mut self, img: &Gray<'_>, count: usize) -> Result<(), VisionError> {
        check(img, count)?;
        self.crop = None;
        self.build_from(img, img.full(), count);
        Ok(())
    }

    /// Builds `count` levels of the part of `img` that [`coarse_to_fine`] reads when it searches
    /// `window`: the window widened to whole coarsest-level pixels. Each level is then the
    /// matching part of the whole frame's level, so the search finds the same match; window
    /// errors are reported as for the whole frame.
    pub fn build_around(&mut self, img: &Gray<'_>, window: Rect, count: usize) -> Result<(), VisionError> {
        check(img, count)?;
        let w = window.inside(img.width, img.height)?;
        let unit = 1usize << (count - 1);
        let part = Rect::new(
            w.x0 & !(unit - 1),
            w.y0 & !(unit - 1),
            w.x1.next_multiple_of(unit).min(img.width),
            w.y1.next_multiple_of(unit).min(img.height),
        );
        self.crop = Some(Crop { origin: (part.x0, part.y0), frame: (img.width, img.height) });
        self.build_from(img, part, count);
        Ok(())
    }

    /// Level 0 = the `part` of `img`, and its halvings.
    fn build_from(&mut self, img: &Gray<'_>, part: Rect, count: usize) {
        self.levels.resize_with(count, GrayBuf::default);
        let base = &mut self.levels[0];
        (base.width, base.height) = (part.width(), part.height());
        base.data.clear();
        for y in part.y0..part.y1 {
            base.data.extend_from_slice(&img.row(y)[part.x0..part.x1]);
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
    }

    /// Level `k`'s offset in the frame's level `k`, and that level's size (the levels' own size
    /// for a pyramid of the whole frame).
    fn placement(&self, k: usize) -> ((usize, usize), (usize, usize)) {
        match self.crop {
            Some(c) => ((c.origin.0 >> k, c.origin.1 >> k), (c.frame.0 >> k, c.frame.1 >> k)),
            None => ((0, 0), (self.levels[k].width, self.levels[k].height)),
        }
    }
}

/// Whether `count` levels of `img` can be built.
fn check(img: &Gray<'_>, count: usize) -> Result<(), VisionError> {
    if count == 0 || img.width >> (count - 1) < 2 || img.height >> (count - 1) < 2 {
        return Err(VisionError::BadParameter(format!(
            "{count} levels of a {}x{} image",
            img.width, img.height
        )));
    }
    Ok(())
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
        // Checked against the frame's level, as a whole-frame pyramid would be, then moved into
        // this pyramid's part of it.
        let ((ox, oy), (fw, fh)) = image.placement(k);
        let win = win.inside(fw, fh)?;
        if t.width > win.width() || t.height > win.height() {
            return Err(VisionError::TemplateTooLarge(t.width, t.height, win));
        }
        let local = Rect::new(win.x0 - ox, win.y0 - oy, win.x1 - ox, win.y1 - oy);
        let m = correlator.best_at(&img, local, &t, (ox, oy))?;
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
            // Built over a window only: the same match, bit for bit.
            for win in [Rect::new(x - 30, y - 27, x + 61, y + 45), Rect::new(x - 5, y - 3, x + 37, y + 35)] {
                let mut part = Pyramid::default();
                part.build_around(&img.view(), win, 3).expect("pyramid");
                let mut whole = Correlator::default();
                let want = coarse_to_fine(&pi, &pt, win, 2, &mut whole);
                let got = coarse_to_fine(&part, &pt, win, 2, &mut c);
                assert_eq!(format!("{got:?}"), format!("{want:?}"), "window {win}");
                assert!(got.is_ok(), "window {win}");
            }
        }
        let mut part = Pyramid::default();
        part.build_around(&img.view(), Rect::new(600, 10, 640, 30), 3).expect("pyramid");
        let want = coarse_to_fine(&pi, &pt, Rect::new(600, 10, 640, 30), 2, &mut c);
        let got = coarse_to_fine(&part, &pt, Rect::new(600, 10, 640, 30), 2, &mut c);
        assert_eq!(got, want, "too small a window is the same error");
        assert!(got.is_err());
        assert!(pi.build(&img.view(), 10).is_err(), "too many levels");
    }
}
