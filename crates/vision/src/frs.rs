//! The fast region segmenter (001 §2.2): a look-up table classifies each pixel by its value
//! into a region class (ranges that come from stored knowledge of the object, or from the last
//! frame), connected components group the classified pixels, and each region's statistics are
//! collected. [`RegionTracker`] feeds a region's statistics forward: the next frame's range is
//! the tracked region's mean plus or minus a few standard deviations, and the region kept is
//! the one of that class nearest where it was.

use crate::image::{Gray, Rect, VisionError};
use crate::regions::{Moments, Runs};
use crate::simd::Path;

/// One class: pixel values `lo ..= hi` are labelled `class` (1 to 15).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClassRange {
    pub lo: u8,
    pub hi: u8,
    pub class: u8,
}

/// A segmented region with its statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    pub class: u8,
    pub area: u32,
    /// Inclusive bounding box, image pixels.
    pub bbox: [u32; 4],
    /// Centroid of the pixel centres.
    pub centroid: [f32; 2],
    pub mean: f32,
    pub sd: f32,
}

/// The segmenter with its buffers.
#[derive(Debug, Default)]
pub struct Frs {
    lut: Vec<u8>,
    labels: Vec<u8>,
    runs: Runs,
    moments: Vec<Moments>,
    regions: Vec<Region>,
    path: Option<Path>,
}

impl Frs {
    /// Runs on `path` from now on (lowered to the fastest the CPU has): every path finds the
    /// same regions, bit for bit.
    pub fn set_path(&mut self, path: Path) {
        self.path = Some(Path::clamp(path));
    }

    /// The regions of at least `min_area` pixels in `window`, largest first. Where ranges
    /// overlap, the first listed wins.
    pub fn segment(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        ranges: &[ClassRange],
        min_area: u32,
    ) -> Result<&[Region], VisionError> {
        let w = window.inside(img.width, img.height)?;
        if ranges.is_empty() || ranges.iter().any(|r| r.lo > r.hi || !(1..=15).contains(&r.class)) {
            return Err(VisionError::BadParameter(format!(
                "FRS ranges {ranges:?}: need lo <= hi, class 1..=15"
            )));
        }
        self.lut.clear();
        self.lut.resize(256, 0);
        for r in ranges.iter().rev() {
            self.lut[r.lo as usize..=r.hi as usize].fill(r.class);
        }
        let (ww, wh) = (w.width(), w.height());
        self.labels.clear();
        self.labels.resize(ww * wh, 0);
        for y in 0..wh {
            let src = &img.row(w.y0 + y)[w.x0..w.x1];
            let lut: &[u8; 256] = self.lut.as_slice().try_into().unwrap_or(&[0; 256]);
            for (l, &v) in self.labels[y * ww..(y + 1) * ww].iter_mut().zip(src) {
                *l = lut[v as usize];
            }
        }
        self.runs.build(&self.labels, ww, wh, false, self.path.unwrap_or_else(Path::active));
        let origin = [w.x0 as f64 + 0.5, w.y0 as f64 + 0.5];
        self.runs.moments(origin, &mut self.moments, |x, y| f32::from(img.at(w.x0 + x, w.y0 + y)));
        self.regions.clear();
        self.regions.extend(self.moments.iter().filter(|m| m.n >= f64::from(min_area)).map(|m| {
            let [cx, cy] = m.centroid();
            let mean = m.value / m.n;
            Region {
                class: m.class,
                area: m.n as u32,
                bbox: [
                    (m.x_min - 0.5) as u32,
                    (m.y_min - 0.5) as u32,
                    (m.x_max - 0.5) as u32,
                    (m.y_max - 0.5) as u32,
                ],
                centroid: [cx as f32, cy as f32],
                mean: mean as f32,
                sd: (m.value_sq / m.n - mean * mean).max(0.0).sqrt() as f32,
            }
        }));
        // A total order (regions do not share a bounding box and class), unstable: no allocation.
        self.regions.sort_unstable_by(|a, b| {
            b.area.cmp(&a.area).then(a.bbox.cmp(&b.bbox)).then(a.class.cmp(&b.class))
        });
        Ok(&self.regions)
    }
}

/// Feed-forward of one region from frame to frame: bootstrap with a range from stored
/// knowledge, then update it from what was found.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionTracker {
    pub range: (u8, u8),
    /// The range for the next frame spans this many standard deviations each side of the mean,
    /// plus `margin` grey levels for what changes between frames (001 §2.1: "a considerable
    /// margin for error").
    pub spread_sd: f32,
    pub margin: f32,
    pub min_area: u32,
    /// Where the region was last seen (bootstrap: `None`, take the largest).
    pub last: Option<Region>,
}

impl RegionTracker {
    pub fn new(range: (u8, u8), spread_sd: f32, margin: f32, min_area: u32) -> Self {
        Self { range, spread_sd, margin, min_area, last: None }
    }

    /// Segments `window` with the current range; keeps the region nearest the last one (the
    /// largest at bootstrap) and feeds its statistics forward. `None`: not found, range kept.
    pub fn update(
        &mut self,
        frs: &mut Frs,
        img: &Gray<'_>,
        window: Rect,
    ) -> Result<Option<Region>, VisionError> {
        let ranges = [ClassRange { lo: self.range.0, hi: self.range.1, class: 1 }];
        let found = frs.segment(img, window, &ranges, self.min_area)?;
        let pick = match &self.last {
            None => found.first().copied(),
            Some(l) => found.iter().copied().min_by(|a, b| {
                let d = |r: &Region| (r.centroid[0] - l.centroid[0]).hypot(r.centroid[1] - l.centroid[1]);
                d(a).total_cmp(&d(b))
            }),
        };
        if let Some(r) = pick {
            let half = self.spread_sd * r.sd + self.margin;
            self.range = ((r.mean - half).clamp(0.0, 255.0) as u8, (r.mean + half).clamp(0.0, 255.0) as u8);
            self.last = Some(r);
        }
        Ok(pick)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::GrayBuf;

    #[test]
    fn regions_come_out_with_their_statistics() {
        // A mid-grey ground with a dark L-shaped region and a bright square.
        let img = GrayBuf::from_fn(80, 60, |x, y| {
            if (10..20).contains(&x) && (10..50).contains(&y)
                || (10..40).contains(&x) && (40..50).contains(&y)
            {
                30 + (x % 3) as u8
            } else if (50..70).contains(&x) && (5..25).contains(&y) {
                220
            } else {
                128
            }
        });
        let ranges = [ClassRange { lo: 0, hi: 60, class: 1 }, ClassRange { lo: 200, hi: 255, class: 2 }];
        let mut f = Frs::default();
        let r = f.segment(&img.view(), img.view().full(), &ranges, 10).expect("segments").to_vec();
        assert_eq!(r.len(), 2, "{r:#?}");
        let (dark, bright) = (r[0], r[1]);
        assert_eq!((dark.class, dark.area, dark.bbox), (1, 10 * 40 + 20 * 10, [10, 10, 39, 49]));
        assert_eq!((bright.class, bright.area, bright.bbox), (2, 400, [50, 5, 69, 24]));
        assert_eq!(bright.centroid, [60.0, 15.0]);
        assert_eq!((bright.mean, bright.sd), (220.0, 0.0));
        let px: Vec<f64> = img.data.iter().filter(|&&v| v < 60).map(|&v| f64::from(v)).collect();
        let mean = px.iter().sum::<f64>() / px.len() as f64;
        let sd = (px.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / px.len() as f64).sqrt();
        assert!(
            (f64::from(dark.mean) - mean).abs() < 1e-4 && (f64::from(dark.sd) - sd).abs() < 1e-4,
            "{dark:?}"
        );
        // Scoped to a window, only what lies inside is seen.
        let part = f.segment(&img.view(), Rect::new(45, 0, 80, 30), &ranges, 10).expect("segments").to_vec();
        assert_eq!(part.len(), 1);
        assert_eq!(part[0].area, 400);
    }

    #[test]
    fn the_tracker_follows_a_region_whose_brightness_drifts() {
        let mut t = RegionTracker::new((150, 255), 3.0, 8.0, 20);
        let mut frs = Frs::default();
        let mut x = 10;
        for k in 0..12u8 {
            // The square moves right 3 px a frame and dims by 8 grey levels a frame, leaving
            // the bootstrap range after a few frames.
            let level = 200 - 8 * k;
            let img = GrayBuf::from_fn(120, 40, |px, py| {
                let noise = ((px * 7 + py * 13 + k as usize) % 5) as u8;
                if (x..x + 12).contains(&px) && (10..22).contains(&py) { level + noise } else { 60 + noise }
            });
            let r = t.update(&mut frs, &img.view(), img.view().full()).expect("runs").expect("found");
            assert!((r.centroid[0] - (x as f32 + 6.0)).abs() < 0.6, "frame {k}: {r:?}");
            assert_eq!(r.area, 144, "frame {k}");
            x += 3;
        }
        assert!(t.range.1 < 150, "the range followed the region down: {:?}", t.range);
    }

    #[test]
    fn bad_ranges_are_errors() {
        let img = GrayBuf::new(8, 8);
        let mut f = Frs::default();
        assert!(f.segment(&img.view(), img.view().full(), &[], 1).is_err());
        assert!(
            f.segment(&img.view(), img.view().full(), &[ClassRange { lo: 9, hi: 3, class: 1 }], 1).is_err()
        );
        assert!(
            f.segment(&img.view(), img.view().full(), &[ClassRange { lo: 0, hi: 3, class: 16 }], 1).is_err()
        );
    }
}
