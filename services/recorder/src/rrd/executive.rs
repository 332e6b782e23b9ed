//! How the executive's own working is drawn: each action-level correction as plots (heading
//! error, turn, estimated offset from the line) and a log line.

use harvey_msgs::ServoCorrection;

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
}
