//! How the executive's own working is drawn: each action-level correction as plots (heading
//! error, turn, estimated offset from the line) and a log line; each pose refinement as the
//! expected and refined poses in the world view and a log line.

use harvey_msgs::{PoseFix, ServoCorrection};

use super::RrdWriter;
use crate::RecordError;

impl RrdWriter {
    pub fn servo(&mut self, c: &ServoCorrection) -> Result<(), RecordError> {
        self.at(c.header.stamp_ns);
        for (path, v) in [
            ("plots/servo_heading_error_deg", c.heading_error_rad.to_degrees()),
            ("plots/servo_correction_deg", c.correction_rad.to_degrees()),
            ("plots/servo_offset_estimate_m", c.offset_m),
        ] {
            self.rec.log(path, &rerun::Scalars::single(v)).map_err(|e| self.err(e))?;
        }
        let text = format!(
            "servo after increment {}: landmark {} at ({:.1}, {:.1}) px, heading error {:.2} deg, turn {:.2} deg",
            c.increment,
            c.landmark_index,
            c.found_px[0],
            c.found_px[1],
            c.heading_error_rad.to_degrees(),
            c.correction_rad.to_degrees()
        );
        self.rec
            .log("log", &rerun::TextLog::new(text).with_level(rerun::TextLogLevel::INFO))
            .map_err(|e| self.err(e))
    }

    pub fn pose_fix(&mut self, p: &PoseFix) -> Result<(), RecordError> {
        self.at(p.header.stamp_ns);
        let expected = super::pose_arrow(&p.expected, rerun::Color::from_rgb(200, 120, 40));
        self.rec.log("world/pose_fix/expected", &expected).map_err(|e| self.err(e))?;
        let refined = super::pose_arrow(&p.refined, rerun::Color::from_rgb(40, 160, 220));
        self.rec.log("world/pose_fix/refined", &refined).map_err(|e| self.err(e))?;
        let text = format!(
            "pose refined from ({:.3}, {:.3}) to ({:.3}, {:.3}) m, heading {:.2} deg: {} of {} vertices found, {} kept, {:.2} px rms",
            p.expected.x_m,
            p.expected.y_m,
            p.refined.x_m,
            p.refined.y_m,
            p.refined.heading_rad.to_degrees(),
            p.found,
            p.asked,
            p.kept,
            p.rms_px
        );
        self.rec
            .log("log", &rerun::TextLog::new(text).with_level(rerun::TextLogLevel::INFO))
            .map_err(|e| self.err(e))
    }
}
