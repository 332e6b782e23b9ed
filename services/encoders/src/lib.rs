//! The encoders service's logic (001 §4, §6.1): shaft-encoder reports become odometry that
//! carries the commanded motion and the progress made on it, for the UMS's growth and the
//! executive's monitoring.

pub mod node;
use harvey_geometry::wrap;
use harvey_msgs::{EncodersRaw, Header, MotionCommand, Odometry, Pose2};

/// Why an encoder report was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EncoderError {
    #[error("encoder report at {stamp_ns} ns is older than the last ({last_ns} ns)")]
    OutOfOrder { stamp_ns: u64, last_ns: u64 },
    #[error("encoder report holds a non-finite number")]
    NotFinite,
}

/// Odometry state: the last command and where the encoders stood when the DRV accepted it.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct OdometryBuilder {
    command: MotionCommand,
    /// Encoder pose just before the current command took effect.
    start: Option<Pose2>,
    /// The pose of the previous report: the last one before a newly accepted command moved.
    previous: Option<Pose2>,
    seq: u64,
    last_stamp_ns: u64,
}

impl OdometryBuilder {
    /// A command sent to the vehicle (panic stops included).
    pub fn on_command(&mut self, cmd: &MotionCommand) {
        self.command = *cmd;
        self.start = None;
    }

    /// One encoder report; reports older than the last are refused.
    pub fn on_encoders(&mut self, e: &EncodersRaw) -> Result<Odometry, EncoderError> {
        if e.header.stamp_ns < self.last_stamp_ns {
            return Err(EncoderError::OutOfOrder {
                stamp_ns: e.header.stamp_ns,
                last_ns: self.last_stamp_ns,
            });
        }
        if !(e.x_m.is_finite() && e.y_m.is_finite() && e.heading_rad.is_finite()) {
            return Err(EncoderError::NotFinite);
        }
        self.last_stamp_ns = e.header.stamp_ns;
        let pose = Pose2 { x_m: e.x_m, y_m: e.y_m, heading_rad: e.heading_rad };
        let accepted = self.command.command_id != 0 && e.command_id == self.command.command_id;
        if accepted && self.start.is_none() {
            // The DRV's first report naming the command already includes its first tick of
            // motion: count from the report before it.
            self.start = Some(self.previous.unwrap_or(pose));
        }
        self.previous = Some(pose);
        let (travelled_m, turned_rad) = match self.start {
            Some(s) => ((pose.x_m - s.x_m).hypot(pose.y_m - s.y_m), wrap(pose.heading_rad - s.heading_rad)),
            None => (0.0, 0.0),
        };
        self.seq += 1;
        Ok(Odometry {
            header: Header::new(self.seq, e.header.stamp_ns),
            world_from_robot: pose,
            travelled_m,
            turned_rad,
            command: self.command,
            moving: e.moving,
            command_accepted: u32::from(accepted),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::CommandKind;

    fn enc(stamp_ns: u64, x_m: f64, heading_rad: f64, command_id: u32, moving: u32) -> EncodersRaw {
        EncodersRaw { header: Header::new(1, stamp_ns), x_m, y_m: 0.0, heading_rad, moving, command_id }
    }

    #[test]
    fn progress_counts_from_acceptance() {
        let mut o = OdometryBuilder::default();
        o.on_encoders(&enc(1, 0.5, 0.0, 0, 0)).expect("ok");
        o.on_command(&MotionCommand {
            kind: CommandKind::Move as u32,
            distance_m: 2.0,
            command_id: 3,
            ..Default::default()
        });
        let before = o.on_encoders(&enc(2, 0.5, 0.0, 0, 0)).expect("ok");
        assert_eq!((before.command_accepted, before.travelled_m), (0, 0.0));
        // The first report naming the command has already moved 0.1 m: it counts.
        let first = o.on_encoders(&enc(3, 0.6, 0.0, 3, 1)).expect("ok");
        assert!((first.travelled_m - 0.1).abs() < 1e-12, "{}", first.travelled_m);
        let later = o.on_encoders(&enc(4, 1.7, 0.0, 3, 1)).expect("ok");
        assert_eq!(later.command_accepted, 1);
        assert!((later.travelled_m - 1.2).abs() < 1e-12);
        assert_eq!(later.command.distance_m, 2.0);
    }

    #[test]
    fn turns_wrap_and_bad_reports_are_refused() {
        let mut o = OdometryBuilder::default();
        o.on_command(&MotionCommand { kind: CommandKind::Turn as u32, command_id: 1, ..Default::default() });
        o.on_encoders(&enc(10, 0.0, 6.2, 1, 1)).expect("ok");
        let t = o.on_encoders(&enc(20, 0.0, 0.1, 1, 0)).expect("ok");
        assert!((t.turned_rad - (0.1 + std::f64::consts::TAU - 6.2)).abs() < 1e-9, "{}", t.turned_rad);
        let e = o.on_encoders(&enc(5, 0.0, 0.0, 1, 0)).expect_err("out of order");
        assert_eq!(e.to_string(), "encoder report at 5 ns is older than the last (20 ns)");
        let e = o.on_encoders(&enc(30, f64::NAN, 0.0, 1, 0)).expect_err("NaN");
        assert_eq!(e.to_string(), "encoder report holds a non-finite number");
    }
}
