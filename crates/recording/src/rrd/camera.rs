//! The camera view: each frame, the Expecter's windows labelled with their landmark's name (taken
//! off once not renewed, as are stale vision results), recognised landmarks as a line at their bearing, and the features a
//! vision worker found.

use harvey_msgs::{Detections, Expectation, FrameHeader, LandmarkSighting};

use super::{RrdError, RrdWriter, colour};

/// A window not renewed for this long (message time) is taken off the image; a vision result
/// no newer one has replaced, after this long.
const WINDOW_LIFETIME_NS: u64 = 300_000_000;
const RESULT_LIFETIME_NS: u64 = 500_000_000;

/// The overlays last drawn before `now_ns - lifetime_ns`, taken out of `drawn`.
fn take_stale(drawn: &mut std::collections::BTreeMap<u32, u64>, lifetime_ns: u64, now_ns: u64) -> Vec<u32> {
    let stale: Vec<u32> = drawn.iter().filter(|(_, t)| **t + lifetime_ns < now_ns).map(|(i, _)| *i).collect();
    for i in &stale {
        drawn.remove(i);
    }
    stale
}

impl RrdWriter {
    pub fn frame(&mut self, h: &FrameHeader, pixels: &[u8]) -> Result<(), RrdError> {
        self.at(h.stamp_ns);
        self.rec.set_time_sequence("frame", h.seq as i64);
        let size = [h.width_px, h.height_px];
        // The left view (the only one of a single camera) under the overlays, which are in its
        // pixels; a stereo pair's right view beside it.
        for (k, entity) in [(0, "camera/image"), (1, "camera/right")] {
            let Some(view) = h.view(pixels, k) else { continue };
            let image = match h.encoding() {
                Some(harvey_msgs::Encoding::Rgb8) => rerun::Image::from_rgb24(view.to_vec(), size),
                _ => rerun::Image::from_l8(view.to_vec(), size),
            };
            self.rec.log(entity, &image).map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    fn landmark_name(&self, index: u32) -> String {
        self.landmarks.get(index as usize).map_or_else(|| format!("landmark {index}"), |m| m.name.clone())
    }

    pub fn expectation(&mut self, e: &Expectation) -> Result<(), RrdError> {
        self.at(e.header.stamp_ns);
        self.windows.insert(e.landmark_index, e.header.stamp_ns);
        let [u0, v0, u1, v1] = e.window_px;
        let boxes = rerun::Boxes2D::from_mins_and_sizes([(u0, v0)], [(u1 - u0, v1 - v0)])
            .with_labels([self.landmark_name(e.landmark_index)])
            .with_colors([colour::WINDOW]);
        self.rec
            .log(format!("camera/image/expectations/{}", e.landmark_index), &boxes)
            .map_err(|e| self.err(e))
    }

    /// Takes the windows the Expecter has not renewed, and the vision results no newer one has
    /// replaced, off the image.
    pub(super) fn clear_stale_overlays(&mut self, now_ns: u64) -> Result<(), RrdError> {
        for i in take_stale(&mut self.windows, WINDOW_LIFETIME_NS, now_ns) {
            self.rec
                .log(format!("camera/image/expectations/{i}"), &rerun::Clear::flat())
                .map_err(|e| self.err(e))?;
        }
        for i in take_stale(&mut self.results, RESULT_LIFETIME_NS, now_ns) {
            self.rec
                .log(format!("camera/image/vision/{i}"), &rerun::Clear::flat())
                .map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    /// A recognised landmark: a vertical line at its bearing's column (for class I and II).
    pub fn sighting(&mut self, s: &LandmarkSighting) -> Result<(), RrdError> {
        let Some((f, w, h)) = self.camera else { return Ok(()) };
        self.at(s.header.stamp_ns);
        if s.kind == 1 || s.kind == 2 {
            let u = (w / 2.0 - f * s.a.tan()) as f32;
            let line =
                rerun::LineStrips2D::new([vec![[u, 0.0], [u, h as f32]]]).with_colors([colour::SIGHTING]);
            self.rec
                .log(format!("camera/image/sightings/{}", s.landmark_index), &line)
                .map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    /// A vision worker's features, as points on the image.
    pub fn detections(&mut self, d: &Detections) -> Result<(), RrdError> {
        self.at(d.header.stamp_ns);
        let n = (d.count as usize).min(d.features.len());
        let pts: Vec<[f32; 2]> = d.features[..n].iter().map(|f| [f.x_px, f.y_px]).collect();
        let features = rerun::Points2D::new(pts).with_radii([2.0]).with_colors([colour::FEATURE]);
        self.rec.log("camera/image/features", &features).map_err(|e| self.err(e))
    }
}
