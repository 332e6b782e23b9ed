//! The long-range cues of 004 §4.1 that bring the robot towards a dock: phototropic perception
//! (the brightest region) and activity detection (where successive frames differ, in both
//! variants, `activity.rs`). The dock itself is recognised by `hough`.

pub use crate::activity::{Activity, ActivityDetector, ActivityVote};
use crate::frs::{ClassRange, Frs, Region};
use crate::image::{Gray, Rect, VisionError};

/// Phototropic perception: the largest region within `margin` grey levels of the brightest
/// pixel of `window` (a lamp, a beacon), of at least `min_area` pixels.
pub fn brightest(
    frs: &mut Frs,
    img: &Gray<'_>,
    window: Rect,
    margin: u8,
    min_area: u32,
) -> Result<Option<Region>, VisionError> {
    let w = window.inside(img.width, img.height)?;
    let peak =
        (w.y0..w.y1).map(|y| img.row(y)[w.x0..w.x1].iter().copied().max().unwrap_or(0)).max().unwrap_or(0);
    let ranges = [ClassRange { lo: peak.saturating_sub(margin), hi: 255, class: 1 }];
    Ok(frs.segment(img, w, &ranges, min_area)?.first().copied())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::GrayBuf;

    #[test]
    fn the_brightest_region_is_the_lamp() {
        let img = GrayBuf::from_fn(160, 120, |x, y| {
            if (100..112).contains(&x) && (20..28).contains(&y) {
                250
            } else if (10..60).contains(&x) && (60..100).contains(&y) {
                200 // a pale wall, bright but not the lamp
            } else {
                90
            }
        });
        let mut frs = Frs::default();
        let r = brightest(&mut frs, &img.view(), img.view().full(), 20, 10).expect("runs").expect("found");
        assert_eq!((r.area, r.centroid), (96, [106.0, 24.0]));
    }

    #[test]
    fn activity_is_where_things_move_and_the_vote_variant_ignores_low_contrast_flicker() {
        let frame = |k: usize, noise: bool| {
            GrayBuf::from_fn(120, 80, |x, y| {
                let base = 60 + ((x / 8 + y / 8) % 2 * 40) as u8;
                let flicker = if noise { ((x * 31 + y * 17 + k * 7) % 5) as u8 } else { 0 };
                // An arm sweeping right and back between x = 70 and 100, rows 20-40.
                let arm = 70 + (k * 6) % 30;
                if (arm..arm + 10).contains(&x) && (20..40).contains(&y) { 230 } else { base + flicker }
            })
        };
        let mut diff = ActivityDetector::new(ActivityVote::Difference, 4);
        let mut votes = ActivityDetector::new(ActivityVote::Threshold(20), 4);
        let mut last = (None, None);
        for k in 0..6 {
            let f = frame(k, true);
            last = (
                diff.push(&f.view(), f.view().full()).expect("runs"),
                votes.push(&f.view(), f.view().full()).expect("runs"),
            );
        }
        for a in [last.0.expect("activity"), last.1.expect("activity")] {
            assert!((70.0..110.0).contains(&a.centroid[0]) && (20.0..40.0).contains(&a.centroid[1]), "{a:?}");
        }
        // The running plane equals the plane of the frames kept: a fresh detector fed only the
        // last four frames says the same.
        let mut fresh = ActivityDetector::new(ActivityVote::Difference, 4);
        let mut again = None;
        for k in 2..6 {
            let f = frame(k, true);
            again = fresh.push(&f.view(), f.view().full()).expect("runs");
        }
        assert_eq!(again, last.0);
        // Flicker alone: the difference variant sees it, the vote variant does not.
        let mut diff = ActivityDetector::new(ActivityVote::Difference, 3);
        let mut votes = ActivityDetector::new(ActivityVote::Threshold(20), 3);
        for k in 0..3 {
            let f = GrayBuf::from_fn(120, 80, |x, y| 100 + ((x * 31 + y * 17 + k * 7) % 5) as u8);
            last = (
                diff.push(&f.view(), f.view().full()).expect("runs"),
                votes.push(&f.view(), f.view().full()).expect("runs"),
            );
        }
        assert!(last.0.expect("activity").strength > 0.5);
        assert_eq!(last.1.expect("activity").strength, 0.0);
    }
}
