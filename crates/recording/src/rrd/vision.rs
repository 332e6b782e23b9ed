//! How vision results are drawn on the camera image: lines, corners, region centroids and
//! correlation matches, one entity per request; failed requests go to the log.

use harvey_msgs::{VisionAlgorithm, VisionResult, VisionStatus};

use super::{RrdError, RrdWriter};

impl RrdWriter {
    pub fn vision_result(&mut self, r: &VisionResult) -> Result<(), RrdError> {
        self.at(r.header.stamp_ns);
        let path = format!("camera/image/vision/{}", r.request_id);
        let items = &r.items[..(r.count as usize).min(r.items.len())];
        let status = VisionStatus::from_raw(r.status);
        if status != Some(VisionStatus::Found) {
            self.rec.log(path.as_str(), &rerun::Clear::flat()).map_err(|e| self.err(e))?;
            if status != Some(VisionStatus::NotFound) {
                let text =
                    format!("vision request {} failed on frame {}: {:?}", r.request_id, r.frame_seq, status);
                let log = rerun::TextLog::new(text).with_level(rerun::TextLogLevel::WARN);
                self.rec.log("log", &log).map_err(|e| self.err(e))?;
            }
            return Ok(());
        }
        let colour = rerun::Color::from_rgb(255, 200, 0);
        let points = |f: &dyn Fn(&[f32; 6]) -> String| {
            let pts: Vec<[f32; 2]> = items.iter().map(|i| [i.values[0], i.values[1]]).collect();
            let labels: Vec<String> = items.iter().map(|i| f(&i.values)).collect();
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
                self.rec.log(path.as_str(), &points(&|v| format!("{:.0}", v[2])))
            }
            Some(VisionAlgorithm::RegionSegmenter) => {
                self.rec.log(path.as_str(), &points(&|v| format!("{:.0} px, mean {:.0}", v[2], v[3])))
            }
            Some(VisionAlgorithm::Phototropic) => {
                self.rec.log(path.as_str(), &points(&|v| format!("light {:.0} px", v[2])))
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
                self.rec.log(path.as_str(), &points(&|v| format!("NC {:.3}", v[2])))
            }
            None => return Ok(()),
        };
        logged.map_err(|e| self.err(e))
    }
}
