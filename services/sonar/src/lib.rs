//! The sonar service's logic (001 §3, §6.1–6.2): assembles the 24-sensor ring from the DRV's
//! banks of 8 and runs the panic-stop reflex, whose stop commands go straight to the vehicle
//! while it drives forward;
//! the panic-avoid reflex is in `avoid.rs`.

pub mod approach;
pub mod avoid;
pub mod node;

use harvey_msgs::PANIC_STOP_IDS;
use harvey_msgs::{
    CommandKind, Header, MotionCommand, Odometry, Pose2, SONAR_BANK_SIZE, SONAR_SENSORS, SonarRaw, SonarRing,
};

/// Whether sensor `i` is one the panic-stop watches (within `PANIC_STOP_ARC_RAD` of ahead).
pub(crate) fn watched_ahead(i: usize) -> bool {
    let b = bearing_rad(i);
    b.min(std::f64::consts::TAU - b) <= harvey_msgs::PANIC_STOP_ARC_RAD + 1e-9
}

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
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct SonarRingBuilder {
    ring: SonarRing,
    panic_stop_m: f64,
    /// Consecutive readings under the panic distance a forward sensor must give before the
    /// stop fires (each sensor fires once per three banks).
    confirm: u8,
    /// Each sensor's run of consecutive close readings.
    close_streak: [u8; SONAR_SENSORS],
    panicking: bool,
    seq: u64,
    /// The vehicle's last odometry pose, and whether it advanced along its heading since the
    /// one before.
    #[serde(default)]
    last_pose: Option<Pose2>,
    #[serde(default)]
    forward: bool,
}

/// The vehicle drives forward when its position advances along its heading by more than this
/// between two odometry reports (m; the DRV reports hundredths of a foot, and a vehicle
/// standing or turning on the spot reports the same position).
const FORWARD_STEP_M: f64 = 0.001;

/// A single close reading is not trusted: a Polaroid ring's crosstalk and multipath (001 §3)
/// put a neighbour's short echo on a forward sensor now and then, and in a doorway that echo
/// is the jamb beside the robot. Two in a row from the same sensor (150 ms at 20 Hz banks,
/// 4.5 cm of travel at 0.3 m/s) stop it.
pub const PANIC_CONFIRM: u8 = 2;

impl SonarRingBuilder {
    /// `panic_stop_m`: a reading ahead closer than this stops the robot.
    pub fn new(panic_stop_m: f64) -> Self {
        let mut ring = SonarRing::default();
        for (i, b) in ring.bearing_rad.iter_mut().enumerate() {
            *b = bearing_rad(i) as f32;
        }
        Self {
            ring,
            panic_stop_m,
            confirm: PANIC_CONFIRM,
            close_streak: [0; SONAR_SENSORS],
            panicking: false,
            seq: 0,
            last_pose: None,
            forward: false,
        }
    }

    /// Odometry: whether the vehicle is driving forward. The panic-stop keeps the robot from
    /// driving on into what is ahead (001 §6.2); a robot standing or turning on the spot
    /// before a wall, or backing away from it, is not stopped (the stops, coming with every
    /// bank, would cut short the turn that takes it away).
    pub fn on_odometry(&mut self, o: &Odometry) {
        let p = o.world_from_robot;
        if let Some(q) = self.last_pose {
            let (s, c) = q.heading_rad.sin_cos();
            self.forward = (p.x_m - q.x_m) * c + (p.y_m - q.y_m) * s > FORWARD_STEP_M;
        }
        self.last_pose = Some(p);
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
            let close = echo && f64::from(raw.range_m[k]) < self.panic_stop_m;
            self.close_streak[i] = if close { self.close_streak[i].saturating_add(1) } else { 0 };
        }
        self.seq += 1;
        self.ring.header = Header::new(self.seq, raw.header.stamp_ns);
        let too_close = (0..SONAR_SENSORS).any(|i| watched_ahead(i) && self.close_streak[i] >= self.confirm);
        // 001 §6.2: stop commands keep coming while the obstacle is there and the vehicle
        // drives on towards it (standing or turning away, it is not stopped again; the
        // executive does not send it forward into what the ring's flag says is too close).
        self.panicking = too_close;
        self.ring.panic_stop = u32::from(too_close);
        let panic_stop = (too_close && self.forward).then(|| MotionCommand {
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

    /// Odometry at `x` m along the x axis, heading `heading` radians.
    fn odo(x: f64, heading: f64) -> Odometry {
        Odometry { world_from_robot: Pose2 { x_m: x, y_m: 0.0, heading_rad: heading }, ..Odometry::default() }
    }

    #[test]
    fn an_obstacle_ahead_stops_the_robot_until_it_goes() {
        let mut b = SonarRingBuilder::new(0.61);
        // Driving forward at 0.3 m/s (odometry every 50 ms).
        b.on_odometry(&odo(0.0, 0.0));
        b.on_odometry(&odo(0.015, 0.0));
        let mut ranges = [5.0; 8];
        ranges[0] = 0.4; // sensor 0, straight ahead
        let u = b.on_bank(&bank(0, ranges, 10)).expect("valid");
        assert!(u.panic_stop.is_none(), "one close reading may be crosstalk");
        b.on_bank(&bank(1, [5.0; 8], 11)).expect("valid");
        b.on_bank(&bank(2, [5.0; 8], 12)).expect("valid");
        let u = b.on_bank(&bank(0, ranges, 13)).expect("valid");
        let stop = u.panic_stop.expect("the second in a row fires the panic-stop");
        assert_eq!((stop.kind, stop.urgent), (CommandKind::Stop as u32, 1));
        assert_eq!(stop.command_id & PANIC_STOP_IDS, PANIC_STOP_IDS, "a reflex's id, not 0");
        assert!(b.panicking());
        // Sensor 9 (135 degrees) that close does not stop a robot moving forward.
        let mut side = [5.0; 8];
        side[3] = 0.2;
        assert!(b.on_bank(&bank(0, side, 20)).expect("valid").panic_stop.is_none());
        assert!(!b.panicking());
        // A forward sensor's close reading followed by a far one never stops the robot.
        let mut once = Vec::new();
        for (k, r) in [0.3f32, 5.0, 0.3, 5.0].into_iter().enumerate() {
            let mut ranges = [5.0; 8];
            ranges[0] = r;
            once.push(b.on_bank(&bank(0, ranges, 30 + k as u64)).expect("valid").panic_stop);
        }
        assert!(once.iter().all(Option::is_none));
    }

    #[test]
    fn a_robot_standing_turning_or_backing_before_a_wall_is_not_stopped() {
        let mut b = SonarRingBuilder::new(0.61);
        let mut ranges = [5.0; 8];
        ranges[0] = 0.5; // sensor 0, straight ahead
        let bank0 = |b: &mut SonarRingBuilder, k: u64| b.on_bank(&bank(0, ranges, k)).expect("valid");
        // Facing 90 degrees, standing, then turning on the spot, then backing away: the ring
        // says the wall is too close ahead, and no stop is sent.
        b.on_odometry(&odo(2.0, 1.57));
        for (k, (x, heading)) in [(2.0, 1.57), (2.0, 1.5), (2.0, 1.4), (2.0, 1.3)].into_iter().enumerate() {
            b.on_odometry(&odo(x, heading));
            let u = bank0(&mut b, k as u64);
            assert!(u.panic_stop.is_none(), "standing or turning, bank {k}");
            assert_eq!(u.ring.panic_stop, u32::from(k >= 1), "the ring still tells, bank {k}");
        }
        let mut back = odo(2.0, 0.0);
        back.world_from_robot.y_m = -0.02; // heading 0, moved sideways: not forward
        b.on_odometry(&odo(2.0, 0.0));
        b.on_odometry(&back);
        assert!(bank0(&mut b, 10).panic_stop.is_none(), "sideways");
        b.on_odometry(&odo(1.985, 0.0));
        assert!(bank0(&mut b, 11).panic_stop.is_none(), "backing away");
        // Driving on towards it: stopped.
        b.on_odometry(&odo(2.0, 0.0));
        assert!(bank0(&mut b, 12).panic_stop.is_some(), "driving forward");
    }
}
