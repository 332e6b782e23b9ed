//! Recognising a class II landmark (002 §3.4: a point of known height, a sign on a wall) in the
//! Expecter's window. The map gives the sign's painted region: its size and how much lighter (or
//! darker) than its wall it is. The window's regions past halfway from the window's median to
//! the sign's expected grey (and clear of the sensor noise), lying wholly inside the window, are
//! candidates; a candidate is the sign when it is as tall as the sign would look from the range
//! its own row gives. Exactly one candidate gives the bearing (its centre's column, the slant's
//! perspective taken out) and the
//! horizontal range (its row, through the sign's height above the camera); none is a miss; two
//! are ambiguous and say nothing.

use harvey_msgs::{Expectation, FrameHeader, Header, LandmarkSighting, SightingKind};
use harvey_vision::frs::{ClassRange, Frs};
use harvey_vision::levels::{histogram, percentile};
use harvey_vision::noise::noise_sigma;
use harvey_vision::{Gray, Rect};
use harvey_world::{LandmarkClass, World};

/// A sign's pixels lie this many noise deviations clear of the window's median at least (single
/// pixels of noise past it are left to the size and fill checks).
const NOISE_SIGMAS: f32 = 2.0;
/// A candidate's height in pixels may differ from the one its row implies by this factor either
/// way (blur, a pixel's rounding at a sign a dozen pixels tall, a region cut by the threshold).
const SIZE_SLACK: f64 = 1.6;
/// The smallest candidate counted (pixels).
const MIN_AREA: u32 = 6;
/// A sign is solid paint: a trapezoid fills at least three quarters of its bounding box, a
/// region cut by noise or lit unevenly a little less; speckle (a bright ceiling's broken edge)
/// fills far less.
const MIN_FILL: f64 = 0.6;

/// What the map says of a class II landmark's look.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// The point's height above the camera (m) and how well the map knows it (m).
    pub above_camera_m: f64,
    pub height_sd_m: f64,
    /// The painted region round it: its width and height (m) and its reflectance over its
    /// wall's.
    pub region_width_m: f64,
    pub region_height_m: f64,
    pub contrast: f64,
    /// It is sought only this near (its activation range): nothing further can be it.
    pub max_range_m: f64,
}

impl Point {
    /// The class II landmarks of `world` that stand on a painted region of a wall, by index.
    pub fn of(world: &World) -> Vec<Option<Point>> {
        let cam_h = world.camera.height_m;
        world
            .landmarks
            .iter()
            .map(|l| {
                if l.class != LandmarkClass::II {
                    return None;
                }
                let p = l.position_m;
                world.walls.iter().find_map(|w| {
                    let (along, off) = w.local([p[0], p[1]]);
                    let off = off.abs();
                    let r = w.regions.iter().find(|r| {
                        off < 0.02
                            && (r.along_m[0]..=r.along_m[1]).contains(&along)
                            && (r.height_m[0]..=r.height_m[1]).contains(&p[2])
                    })?;
                    Some(Point {
                        above_camera_m: p[2] - cam_h,
                        height_sd_m: world.survey.position_sd_m.max(l.position_sd_m),
                        region_width_m: r.along_m[1] - r.along_m[0],
                        region_height_m: r.height_m[1] - r.height_m[0],
                        contrast: r.reflectance / w.reflectance,
                        max_range_m: l.activation_range_m,
                    })
                })
            })
            .collect()
    }
}

/// The class II recogniser: the map's signs and the segmenter's buffers.
#[derive(Debug)]
pub struct PointLandmarks {
    points: Vec<Option<Point>>,
    frs: Frs,
    pub focal_px: f64,
    /// The spread of a sign's centre (pixels), the mount's calibration included: across, where
    /// it is four times the box's middle (its edges known to half a pixel) less three times the
    /// centroid, a pixel; down, the centroid's row, half a pixel.
    sd_px: [f64; 2],
}

impl PointLandmarks {
    /// `calibration_sd_rad`: how well the mount's yaw and pitch are known (`[survey]`).
    pub fn new(world: &World, calibration_sd_rad: f64) -> Self {
        let f = world.camera.focal_px;
        Self {
            points: Point::of(world),
            frs: Frs::default(),
            focal_px: f,
            sd_px: [1.0f64.hypot(f * calibration_sd_rad), 0.5f64.hypot(f * calibration_sd_rad)],
        }
    }

    /// Looks for the class II landmark of `e` in a mono8 frame; the sighting's `seq` is left for
    /// the caller to number. `None`: not a class II landmark on a painted region, a window off the
    /// frame or of another size, or an ambiguous window.
    pub fn recognise(&mut self, h: &FrameHeader, pixels: &[u8], e: &Expectation) -> Option<LandmarkSighting> {
        let point = *self.points.get(e.landmark_index as usize)?.as_ref()?;
        let (w, ht) = (h.width_px as usize, h.height_px as usize);
        if e.class != 2 || (e.width_px, e.height_px) != (h.width_px, h.height_px) {
            return None;
        }
        let img = Gray::new(pixels, w, ht, h.stride_bytes as usize).ok()?;
        // The window bounds where the point may be; the sign stands round it, by its size at
        // the depth the window's middle row gives, and the unknown mount moves it by up to three
        // of its deviations.
        let [u0, v0, u1, v1] = e.window_px.map(f64::from);
        let (cx, cy, f) = (w as f64 / 2.0, ht as f64 / 2.0, self.focal_px);
        let mid_depth = f * point.above_camera_m / (cy - (v0 + v1) / 2.0);
        let (pad_u, pad_v) = if mid_depth > 0.0 {
            let half = |size: f64| f * size / mid_depth / 2.0;
            (
                half(point.region_width_m) + 3.0 * self.sd_px[0],
                half(point.region_height_m) + 3.0 * self.sd_px[1],
            )
        } else {
            (0.0, 0.0)
        };
        let clip = |x: f64, max: usize| x.clamp(0.0, max as f64) as usize;
        let win =
            Rect::new(clip(u0 - pad_u, w), clip(v0 - pad_v, ht), clip(u1 + pad_u, w), clip(v1 + pad_v, ht))
                .inside(w, ht)
                .ok()?;
        let background = f32::from(percentile(&histogram(&img, win), 0.5));
        let noise = NOISE_SIGMAS * noise_sigma(&img, win);
        let expected = background * point.contrast as f32;
        let band = if point.contrast >= 1.0 {
            let lo = (background + (expected - background) / 2.0).max(background + noise);
            ClassRange { lo: lo.ceil().min(255.0) as u8, hi: 255, class: 1 }
        } else {
            let hi = (background - (background - expected) / 2.0).min(background - noise);
            ClassRange { lo: 0, hi: hi.floor().max(0.0) as u8, class: 1 }
        };
        let base = LandmarkSighting {
            header: Header::new(0, h.stamp_ns),
            frame_seq: h.seq,
            landmark_index: e.landmark_index,
            ..Default::default()
        };
        let regions = self.frs.segment(&img, win, &[band], MIN_AREA).ok()?;
        let fits: Vec<(f64, f64)> = regions
            .iter()
            .filter(|r| {
                r.bbox[0] > win.x0 as u32
                    && r.bbox[1] > win.y0 as u32
                    && (r.bbox[2] as usize) + 1 < win.x1
                    && (r.bbox[3] as usize) + 1 < win.y1
            })
            .filter_map(|r| {
                // A sign seen at a slant is a trapezoid, its near side taller: its area's centroid
                // lies w dh / 6 sum(h) towards the near side of the middle, the projection of its
                // centre w dh / 2 sum(h) towards the far side; so the centre is the middle less
                // three times the centroid's offset from it.
                let middle = f64::from(r.bbox[0] + r.bbox[2] + 1) / 2.0;
                let [u, v] = [4.0 * middle - 3.0 * f64::from(r.centroid[0]), f64::from(r.centroid[1])];
                // Depth along the optical axis from the row: the sign above (or below) the camera.
                let depth = f * point.above_camera_m / (cy - v);
                let tall = f * point.region_height_m / depth;
                let (seen, across) =
                    (f64::from(r.bbox[3] - r.bbox[1] + 1), f64::from(r.bbox[2] - r.bbox[0] + 1));
                let solid = f64::from(r.area) >= MIN_FILL * seen * across;
                // As tall as the sign from this depth, and no wider (seen at a slant, narrower).
                let wide = f * point.region_width_m / depth;
                let sized = seen < tall * SIZE_SLACK + 1.0
                    && seen > tall / SIZE_SLACK - 1.0
                    && across < wide * SIZE_SLACK + 1.0;
                // Not beyond its activation range: its row at least as far from the horizon as
                // the sign's at that range, less three of the row's deviations (an unknown pitch
                // moves a far sign's row by pixels).
                let off_horizon = (cy - v) * point.above_camera_m.signum();
                let least = f * point.above_camera_m.abs() / point.max_range_m - 3.0 * self.sd_px[1];
                let near = depth > 0.0 && off_horizon >= least.max(0.0);
                // The window was padded for the sign's extent; its centre lies in the window as
                // given, give or take the mount.
                let (mu, mv) = (3.0 * self.sd_px[0], 3.0 * self.sd_px[1]);
                let centred = (u0 - mu..=u1 + mu).contains(&u) && (v0 - mv..=v1 + mv).contains(&v);
                (near && solid && sized && centred).then_some((u, v))
            })
            .collect();
        let [(u, v)] = fits.as_slice() else {
            return fits
                .is_empty()
                .then_some(LandmarkSighting { kind: SightingKind::NotFound as u32, ..base });
        };
        let bearing = ((cx - u) / f).atan();
        let depth = f * point.above_camera_m / (cy - v);
        let range = depth / bearing.cos();
        let range_sd =
            range * (self.sd_px[1] / (cy - v).abs()).hypot(point.height_sd_m / point.above_camera_m.abs());
        Some(LandmarkSighting {
            kind: SightingKind::BearingRange as u32,
            a: bearing,
            a_sd: self.sd_px[0] / f,
            b: range,
            b_sd: range_sd,
            ..base
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hallway_s_signs_are_known_by_their_painted_regions() {
        let w = harvey_world::load_str(include_str!("../../../../worlds/hallway.toml"), "hallway")
            .expect("world");
        let points = Point::of(&w);
        let named = |n: &str| points[w.landmarks.iter().position(|l| l.name == n).expect("landmark")];
        // The office sign: 0.4 x 0.3 m at 1.55 m, 0.95 on a 0.70 wall; the exit sign 0.4 x 0.2 m at
        // 2.2 m, 0.90 on the end wall's 0.60; the camera at 1.2 m.
        let office = named("office-sign").expect("on its region");
        assert!((office.above_camera_m - 0.35).abs() < 1e-9 && (office.region_height_m - 0.3).abs() < 1e-9);
        assert!((office.contrast - 0.95 / 0.70).abs() < 1e-9 && (office.region_width_m - 0.4).abs() < 1e-9);
        let exit = named("exit-sign").expect("on its region");
        assert!((exit.above_camera_m - 1.0).abs() < 1e-9 && (exit.contrast - 1.5).abs() < 1e-9);
        assert_eq!(exit.max_range_m, 17.0);
        // Class I and III landmarks are not points.
        assert!(named("end-wall-corner").is_none() && named("north-baseboard").is_none());
    }
}
