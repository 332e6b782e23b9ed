//! The sonar service's logic (001 §3, §6.1–6.2): assembles the 24-sensor ring from the DRV's
//! banks of 8 and runs the panic-stop reflex, whose stop commands go straight to the vehicle;
//! the panic-avoid reflex is in `avoid.rs`.

pub mod approach;
pub mod avoid;

use harvey_msgs::PANIC_STOP_IDS;
use harvey_msgs::{CommandKind, Header, MotionCommand, SONAR_BANK_SIZE, SONAR_SENSORS, SonarRaw, SonarRing};

/// Sensors whose axis lies within this angle of straight ahead watch for the panic-stop.
const FORWARD_ARC_RAD: f64 = std::f64::consts::FRAC_PI_6 + 1e-9;

/// Bearing of sensor `i`'s axis in the robot frame: evenly round the ring, 0 straight ahead.
pub fn bearing_rad(i: usize) -> f64 {
    i as f64 * std::f64::consts::TAU / SONAR_SENSORS as f64
}

/// Why a bank of readings was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BankError {
    /// The DRV fires banks 0, 1 and 2 only.
    #[error("sonar bank {bank} does not exist (0..=2)")]
    NoSuchBank { bank: u32 },
}

/// What one bank of readings produced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Update {
    pub ring: SonarRing,
    /// An urgent stop for the vehicle, when the reflex fires.
    pub panic_stop: Option<MotionCommand>,
}

/// The ring being assembled and the reflex's state.
#[derive(Debug)]
pub struct SonarRingBuilder {
    ring: SonarRing,
    panic_stop_m: f64,
    panicking: bool,
    seq: u64,
}

impl SonarRingBuilder {
    /// `panic_stop_m`: a reading ahead closer than this stops the robot.
    pub fn new(panic_stop_m: f64) -> Self {
        let mut ring = SonarRing::default();
        for (i, b) in ring.bearing_rad.iter_mut().enumerate() {
            *b = bearing_rad(i) as f32;
        }
        Self { ring, panic_stop_m, panicking: false, seq: 0 }
    }

    /// Folds in one bank; rejects a bank number the DRV cannot send.
    pub fn on_bank(&mut self, raw: &SonarRaw) -> Result<Update, BankError> {
        if raw.bank >= 3 {
            return Err(BankError::NoSuchBank { bank: raw.bank });
        }
        for k in 0..SONAR_BANK_SIZE {
            let i = raw.bank as usize + 3 * k;
            let echo = raw.echo_mask & (1 << k) != 0 && raw.range_m[k].is_finite();
            self.ring.range_m[i] = raw.range_m[k];
            self.ring.reading_stamp_ns[i] = raw.header.stamp_ns;
            if echo {
                self.ring.valid_mask |= 1 << i;
            } else {
                self.ring.valid_mask &= !(1 << i);
            }
        }
        self.seq += 1;
        self.ring.header = Header::new(self.seq, raw.header.stamp_ns);
        let too_close = (0..SONAR_SENSORS).any(|i| {
            let b = bearing_rad(i);
            let ahead = b.min(std::f64::consts::TAU - b) <= FORWARD_ARC_RAD;
            ahead
                && self.ring.valid_mask & (1 << i) != 0
                && f64::from(self.ring.range_m[i]) < self.panic_stop_m
        });
        // 001 §6.2: stop commands keep coming while the obstacle is there.
        self.panicking = too_close;
        self.ring.panic_stop = u32::from(too_close);
        let panic_stop = too_close.then(|| MotionCommand {
            header: self.ring.header,
            kind: CommandKind::Stop as u32,
            urgent: 1,
            // A reflex's id (top bit; the panic-avoid counts below `PANIC_STOP_IDS`), never 0.
            command_id: PANIC_STOP_IDS | (self.seq as u32 & !PANIC_STOP_IDS),
            ..MotionCommand::default()
        });
        Ok(Update { ring: self.ring, panic_stop })
    }

    pub fn panicking(&self) -> bool {
        self.panicking
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bank(bank: u32, ranges: [f32; 8], stamp_ns: u64) -> SonarRaw {
        SonarRaw { header: Header::new(1, stamp_ns), bank, echo_mask: 0xff, range_m: ranges }
    }

    #[test]
    fn banks_fill_the_ring_in_place() {
        let mut b = SonarRingBuilder::new(0.61);
        b.on_bank(&bank(0, [1.0; 8], 10)).expect("valid");
        b.on_bank(&bank(1, [2.0; 8], 20)).expect("valid");
        let u = b.on_bank(&bank(2, [3.0; 8], 30)).expect("valid");
        assert_eq!(u.ring.range_m[0], 1.0);
        assert_eq!(u.ring.range_m[4], 2.0);
        assert_eq!(u.ring.range_m[23], 3.0);
        assert_eq!(u.ring.reading_stamp_ns[23], 30);
        assert_eq!(u.ring.valid_mask, (1 << 24) - 1);
        assert!((f64::from(u.ring.bearing_rad[6]) - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
        let e = b.on_bank(&bank(3, [1.0; 8], 40)).expect_err("no bank 3");
        assert_eq!(e.to_string(), "sonar bank 3 does not exist (0..=2)");
    }

    #[test]
    fn an_obstacle_ahead_stops_the_robot_until_it_goes() {
        let mut b = SonarRingBuilder::new(0.61);
        let mut ranges = [5.0; 8];
        ranges[0] = 0.4; // sensor 0, straight ahead
        let u = b.on_bank(&bank(0, ranges, 10)).expect("valid");
        let stop = u.panic_stop.expect("panic-stop fires");
        assert_eq!((stop.kind, stop.urgent), (CommandKind::Stop as u32, 1));
        assert_eq!(stop.command_id & PANIC_STOP_IDS, PANIC_STOP_IDS, "a reflex's id, not 0");
        assert!(b.panicking());
        // Sensor 9 (135 degrees) that close does not stop a robot moving forward.
        let mut side = [5.0; 8];
        side[3] = 0.2;
        assert!(b.on_bank(&bank(0, side, 20)).expect("valid").panic_stop.is_none());
        assert!(!b.panicking());
    }
}
