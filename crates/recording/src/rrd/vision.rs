//! How vision results are drawn on the camera image: lines, corners, region centroids, the dock,
//! poles, correlation matches (a line from where the vertex was expected to where it was
//! found), the path's edges and centreline, the stereo odometry's obstacle points and depth from
//! motion's tracked points, one entity per request, taken off once stale; labels only where a result has a few
//! items; the light blob's size as a plot; failed requests go to the log.

use harvey_msgs::{VisionAlgorithm, VisionResult, VisionStatus};

use super::{RrdError, RrdWriter};

/// The items of one result that carry a label.
const LABELLED: usize = 3;

impl RrdWriter {
    pub fn vision_result(&mut self, r: &VisionResult) -> Result<(), RrdError> {
        self.at(r.header.stamp_ns);
        let path = format!("camera/image/vision/{}", r.request_id);
        self.results.insert(r.request_id, r.header.stamp_ns);
        let items = &r.items[..(r.count as usize).min(r.items.len())];
        let status = VisionStatus::from_raw(r.status);
        if status != Some(VisionStatus::Found) {
            self.rec.log(path.as_str(), &rerun::Clear::flat()).map_err(|e| self.err(e))?;
            if status != Some(VisionStatus::NotFound) {
                let text = format!("request {} failed on frame {}: {:?}", r.request_id, r.frame_seq, status);
                self.say("vision", rerun::TextLogLevel::WARN, text)?;
            }
            return Ok(());
        }
        let colour = super::colour::RESULT;
        // Labels on the first few items only (strongest, longest or largest first): more would
        // cover the image and each other.
        let points = |f: &dyn Fn(&[f32; 6]) -> String| {
            let pts: Vec<[f32; 2]> = items.iter().map(|i| [i.values[0], i.values[1]]).collect();
            let labels: Vec<String> = items
                .iter()
                .enumerate()
                .map(|(k, i)| if k < LABELLED { f(&i.values) } else { String::new() })
                .collect();
            rerun::Points2D::new(pts).with_labels(labels).with_radii([2.5]).with_colors([colour])
        };
        let logged = match VisionAlgorithm::from_raw(r.algorithm) {
            Some(VisionAlgorithm::LineFinder) => {
                let strips: Vec<Vec<[f32; 2]>> = items
                    .iter()
                    .map(|i| vec![[i.values[0], i.values[1]], [i.values[2], i.values[3]]])
                    .collect();
                self.rec.log(path.as_str(), &rerun::LineStrips2D::new(strips).with_colors([colour]))
            }
            Some(VisionAlgorithm::Moravec) => {
                let pts: Vec<[f32; 2]> = items.iter().map(|i| [i.values[0], i.values[1]]).collect();
                self.rec
                    .log(path.as_str(), &rerun::Points2D::new(pts).with_radii([2.0]).with_colors([colour]))
            }
            Some(VisionAlgorithm::RegionSegmenter) => {
                self.rec.log(path.as_str(), &points(&|v| format!("{:.0} px, mean {:.0}", v[2], v[3])))
            }
            Some(VisionAlgorithm::Phototropic) => {
                // The blob's size goes to a plot: a label here would sit on the other results'.
                if let Some(i) = items.first() {
                    let size = rerun::Scalars::single(f64::from(i.values[2]));
                    self.rec.log("plots/vision/light_px", &size).map_err(|e| self.err(e))?;
                }
                let pts: Vec<[f32; 2]> = items.iter().map(|i| [i.values[0], i.values[1]]).collect();
                self.rec
                    .log(path.as_str(), &rerun::Points2D::new(pts).with_radii([4.0]).with_colors([colour]))
            }
            Some(VisionAlgorithm::Activity) => {
                self.rec.log(path.as_str(), &points(&|v| format!("activity {:.1}", v[2])))
            }
            Some(VisionAlgorithm::Dock) => {
                // The recognised frame: 2 x 1 model units round its centre, `scale` px a unit.
                let boxes: Vec<[f32; 2]> = items.iter().map(|i| [i.values[3], i.values[3] / 2.0]).collect();
                let centres: Vec<[f32; 2]> = items.iter().map(|i| [i.values[0], i.values[1]]).collect();
                let labels: Vec<String> = items.iter().map(|i| format!("dock {:.2}", i.values[2])).collect();
                let frame = rerun::Boxes2D::from_centers_and_half_sizes(centres, boxes)
                    .with_labels(labels)
                    .with_colors([colour]);
                self.rec.log(path.as_str(), &frame)
            }
            Some(VisionAlgorithm::Poles) => {
                let strips: Vec<Vec<[f32; 2]>> = items
                    .iter()
                    .map(|i| vec![[i.values[0], i.values[3]], [i.values[0], i.values[4]]])
                    .collect();
                let labels: Vec<String> = items
                    .iter()
                    .map(|i| format!("pole {:.0} at {:.1} m", i.values[2], i.values[1]))
                    .collect();
                self.rec.log(
                    path.as_str(),
                    &rerun::LineStrips2D::new(strips).with_labels(labels).with_colors([colour]),
                )
            }
            Some(VisionAlgorithm::Correlate) => {
                let moves: Vec<Vec<[f32; 2]>> = items
                    .iter()
                    .map(|i| vec![[i.values[3], i.values[4]], [i.values[0], i.values[1]]])
                    .collect();
                self.rec.log(path.as_str(), &rerun::LineStrips2D::new(moves).with_colors([colour]))
            }
            Some(VisionAlgorithm::Path) => {
                // The centreline and both edges, from the vanishing point down to the window's
                // bottom row, labelled with the fit's confidence.
                let Some(c) = items.first().map(|i| i.values) else { return Ok(()) };
                let (vanishing, bottom_v) = ([c[0], c[1]], c[3]);
                let mut strips = vec![vec![vanishing, [c[2], bottom_v]]];
                strips.extend(items.iter().skip(1).map(|i| {
                    let [u, v, angle, ..] = i.values;
                    let s = angle.sin();
                    let x = if s.abs() < 1e-6 { u } else { u + (bottom_v - v) * angle.cos() / s };
                    vec![vanishing, [x, bottom_v]]
                }));
                let mut labels = vec![String::new(); strips.len()];
                labels[0] = format!("path {:.0} px", c[4]);
                self.rec.log(
                    path.as_str(),
                    &rerun::LineStrips2D::new(strips).with_labels(labels).with_colors([colour]),
                )
            }
            Some(VisionAlgorithm::StereoOdometry) => {
                // The obstacle points (after the motion and the counts) where the left image
                // sees them, the nearest labelled with their distance.
                let obstacles = items.get(2..).unwrap_or_default();
                let pts: Vec<[f32; 2]> = obstacles.iter().map(|i| [i.values[4], i.values[5]]).collect();
                let labels: Vec<String> = obstacles
                    .iter()
                    .enumerate()
                    .map(|(k, i)| {
                        if k < LABELLED {
                            format!("{:.1} m", i.values[0].hypot(i.values[1]))
                        } else {
                            String::new()
                        }
                    })
                    .collect();
                let drawn =
                    rerun::Points2D::new(pts).with_labels(labels).with_radii([3.0]).with_colors([colour]);
                self.rec.log(path.as_str(), &drawn)
            }
            Some(VisionAlgorithm::Depth) => {
                // Each tracked point (after the registration's item), labelled with its depth and
                // spread (the nearest few); those standing off the floor are the obstacles.
                let items = items.get(1..).unwrap_or_default();
                let pts: Vec<[f32; 2]> = items.iter().map(|i| [i.values[0], i.values[1]]).collect();
                let labels: Vec<String> = items
                    .iter()
                    .enumerate()
                    .map(|(k, i)| {
                        let v = i.values;
                        let kind = if v[5] > 0.5 { " obstacle" } else { "" };
                        if k < LABELLED {
                            format!("{:.2} ± {:.2} m{kind}", v[2], v[3])
                        } else {
                            String::new()
                        }
                    })
                    .collect();
                let radii: Vec<f32> =
                    items.iter().map(|i| if i.values[5] > 0.5 { 4.0 } else { 2.0 }).collect();
                let drawn =
                    rerun::Points2D::new(pts).with_labels(labels).with_radii(radii).with_colors([colour]);
                self.rec.log(path.as_str(), &drawn)
            }
            None => return Ok(()),
        };
        logged.map_err(|e| self.err(e))
    }
}
