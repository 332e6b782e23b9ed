//! Panic-avoid (001 §6.2, "flight"): successive time-stamped readings of the sensors ahead are
//! compared; when the range closes faster than the robot's own motion explains, the object is
//! approaching. After several confirming readings with the time to contact under a threshold,
//! the robot stops, turns a right angle towards the clearer side and dashes sideways until no
//! sensor senses the object approaching. Its commands are urgent: they go straight to the
//! vehicle and override whatever the executive had commanded. The panic-stop stays in play.

use harvey_msgs::{CommandKind, Header, MotionCommand, Odometry, SONAR_SENSORS, SonarRing};

use crate::approach::{Approach, ApproachParams};
use crate::bearing_rad;

/// Command ids of the reflex: the top bit set, so they never clash with the executive's.
const ID_BASE: u32 = harvey_msgs::REFLEX_ID_BIT;

/// Settings (the paper gives the right-angle turn; the rest are this system's choices).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AvoidParams {
    /// Time to contact (s) under which an approaching object counts.
    pub ttc_s: f64,
    /// Consecutive confirming readings of one sensor that trigger the evasion.
    pub confirm: u32,
    /// Least speed (m/s) of the object itself towards the robot.
    pub min_approach_mps: f64,
    /// Sensors within this angle of straight ahead watch for a head-on approach.
    pub arc_rad: f64,
    /// The turn before the dash (001 §6.2: 90 degrees).
    pub turn_rad: f64,
    /// Length of one sideways dash (m).
    pub dash_m: f64,
    /// The panic-stop distance (m): no dash heads for anything nearer than this plus the dash.
    pub stop_m: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    Watching,
    /// Stop sent; waiting for the vehicle to be still.
    Stopping,
    Turning {
        id: u32,
        sent_ns: u64,
    },
    Dashing {
        id: u32,
        sent_ns: u64,
    },
    /// No room for another dash: the robot keeps still (an urgent stop every `HOLD_NS`) until
    /// the object stops approaching.
    Holding {
        sent_ns: u64,
    },
}

/// While holding, the stop is repeated this often (ns), so that the executive sees the reflex
/// still has the vehicle.
const HOLD_NS: u64 = 500_000_000;

/// A step the vehicle neither ran nor is running after this long is sent again (the vehicle
/// refused it, or another command took its place).
const RESEND_NS: u64 = 1_000_000_000;

/// A dash stops this far (m) short of the panic-stop distance from what is ahead, and one
/// shorter than `MIN_DASH_M` is not worth making.
const DASH_MARGIN_M: f64 = 0.05;
const MIN_DASH_M: f64 = 0.1;

/// A sensor's readings over a turn of more than this (3 degrees) are not compared.
const MAX_TURN_RAD: f64 = 0.052;

/// The reflex's state: the approach detector, the evasion's phase.
#[derive(Debug)]
pub struct PanicAvoid {
    p: AvoidParams,
    approach: Approach,
    /// Set by the latest ring: some sensor (any bearing) saw an approach.
    approaching: bool,
    /// Clearance at the left, right and straight ahead (m) from the latest ring.
    clearance: [f64; 2],
    ahead_m: f64,
    /// The way to turn: +1 left, -1 right (away from the object, else to the clearer side).
    away: f64,
    moving: bool,
    phase: Phase,
    next_id: u32,
    /// Evasions started.
    pub episodes: u32,
}

impl PanicAvoid {
    pub fn new(p: AvoidParams) -> Self {
        let approach = Approach::new(ApproachParams {
            min_approach_mps: p.min_approach_mps,
            ttc_s: p.ttc_s,
            max_turn_rad: MAX_TURN_RAD,
        });
        Self {
            p,
            approach,
            approaching: false,
            clearance: [0.0; 2],
            ahead_m: 0.0,
            away: 1.0,
            moving: false,
            phase: Phase::Watching,
            next_id: ID_BASE,
            episodes: 0,
        }
    }

    /// Whether an evasion is under way.
    pub fn evading(&self) -> bool {
        self.phase != Phase::Watching
    }

    fn command(
        &mut self,
        kind: CommandKind,
        stamp_ns: u64,
        distance_m: f64,
        angle_rad: f64,
    ) -> MotionCommand {
        // Top bit set, second clear: below the panic-stop's ids.
        self.next_id = (self.next_id.wrapping_add(1) & !harvey_msgs::PANIC_STOP_IDS) | ID_BASE;
        MotionCommand {
            header: Header::new(u64::from(self.next_id & !ID_BASE), stamp_ns),
            kind: kind as u32,
            urgent: 1,
            distance_m,
            angle_rad,
            command_id: self.next_id,
            ..MotionCommand::default()
        }
    }

    /// Odometry: the robot's motion for the approach detector; advances an evasion when the
    /// vehicle has finished its last step.
    pub fn on_odometry(&mut self, o: &Odometry) -> Option<MotionCommand> {
        let t = o.header.stamp_ns;
        self.approach.on_odometry(o);
        self.moving = o.moving != 0;
        let finished = |id: u32| o.command.command_id == id && o.command_accepted == 1 && o.moving == 0;
        let lost = |id: u32, sent: u64| o.command.command_id != id && o.moving == 0 && t > sent + RESEND_NS;
        let turn = self.away * self.p.turn_rad;
        match self.phase {
            // Away from the object (left is a positive turn).
            Phase::Stopping if !self.moving => Some(self.turn(t, turn)),
            Phase::Turning { id, sent_ns } if lost(id, sent_ns) => Some(self.turn(t, turn)),
            Phase::Dashing { id, sent_ns } if lost(id, sent_ns) => {
                Some(self.dash(t, self.dash_room().max(0.0)))
            }
            Phase::Turning { id, .. } | Phase::Dashing { id, .. } if finished(id) => {
                let first = matches!(self.phase, Phase::Turning { .. });
                // A dash, and more while the object still approaches, cut short of anything
                // ahead (the panic-stop would freeze the robot there anyway).
                let room = self.dash_room();
                if (first || self.approaching) && room >= MIN_DASH_M {
                    return Some(self.dash(t, room));
                }
                if self.approaching {
                    return Some(self.hold(t));
                }
                self.phase = Phase::Watching;
                None
            }
            Phase::Holding { .. } if !self.approaching => {
                self.phase = Phase::Watching;
                None
            }
            Phase::Holding { sent_ns } if t >= sent_ns + HOLD_NS => Some(self.hold(t)),
            _ => None,
        }
    }

    fn turn(&mut self, t: u64, angle_rad: f64) -> MotionCommand {
        let c = self.command(CommandKind::Turn, t, 0.0, angle_rad);
        self.phase = Phase::Turning { id: c.command_id, sent_ns: t };
        c
    }

    /// How far a dash may go: its length, cut short of what is ahead.
    fn dash_room(&self) -> f64 {
        (self.ahead_m - self.p.stop_m - DASH_MARGIN_M).min(self.p.dash_m)
    }

    fn hold(&mut self, t: u64) -> MotionCommand {
        self.phase = Phase::Holding { sent_ns: t };
        self.command(CommandKind::Stop, t, 0.0, 0.0)
    }

    fn dash(&mut self, t: u64, length_m: f64) -> MotionCommand {
        let c = self.command(CommandKind::Move, t, length_m, 0.0);
        self.phase = Phase::Dashing { id: c.command_id, sent_ns: t };
        c
    }

    /// Folds in a ring; returns the urgent stop that starts an evasion.
    pub fn on_ring(&mut self, ring: &SonarRing) -> Option<MotionCommand> {
        self.approaching = self.approach.on_ring(ring) != 0;
        let trigger = (0..SONAR_SENSORS).any(|i| {
            let b = bearing_rad(i);
            b.min(std::f64::consts::TAU - b) <= self.p.arc_rad && self.approach.streak(i) >= self.p.confirm
        });
        let side = |i: usize| {
            if ring.valid_mask & (1 << i) != 0 { f64::from(ring.range_m[i]) } else { f64::INFINITY }
        };
        let quarter = SONAR_SENSORS / 4;
        self.clearance = [side(quarter), side(3 * quarter)];
        self.ahead_m = side(0);
        if trigger && self.phase == Phase::Watching {
            // Away from the side the approaching echoes come from; the clearer side on a tie.
            let side: f64 = (0..SONAR_SENSORS)
                .filter(|&i| self.approach.streak(i) > 0)
                .map(|i| bearing_rad(i).sin())
                .filter(|s| s.abs() > 1e-9 && s.abs() < self.p.arc_rad.sin() + 1e-9)
                .sum();
            self.away = match side {
                s if s < -1e-9 => 1.0,
                s if s > 1e-9 => -1.0,
                _ if self.clearance[0] >= self.clearance[1] => 1.0,
                _ => -1.0,
            };
            self.episodes += 1;
            self.phase = Phase::Stopping;
            return Some(self.command(CommandKind::Stop, ring.header.stamp_ns, 0.0, 0.0));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::Pose2;

    const P: AvoidParams = AvoidParams {
        ttc_s: 4.0,
        confirm: 3,
        min_approach_mps: 0.15,
        arc_rad: std::f64::consts::FRAC_PI_6,
        turn_rad: std::f64::consts::FRAC_PI_2,
        dash_m: 0.9,
        stop_m: 0.61,
    };

    /// A ring read at `t` s: `ahead` m on sensor 0, `left` and `right` on sensors 6 and 18,
    /// 8 m elsewhere.
    fn ring(t: f64, ahead: f32, left: f32, right: f32) -> SonarRing {
        let mut r = SonarRing {
            header: Header::new(1, (t * 1e9) as u64),
            valid_mask: (1 << 24) - 1,
            ..Default::default()
        };
        r.range_m = [8.0; SONAR_SENSORS];
        (r.range_m[0], r.range_m[6], r.range_m[18]) = (ahead, left, right);
        r.reading_stamp_ns = [(t * 1e9) as u64; SONAR_SENSORS];
        r
    }

    fn odo(t: f64, x: f64, moving: bool, id: u32) -> Odometry {
        Odometry {
            header: Header::new(1, (t * 1e9) as u64),
            world_from_robot: Pose2 { x_m: x, ..Pose2::default() },
            moving: u32::from(moving),
            command: MotionCommand { command_id: id, ..MotionCommand::default() },
            command_accepted: 1,
            ..Odometry::default()
        }
    }

    #[test]
    fn driving_at_a_wall_is_no_approach() {
        let mut a = PanicAvoid::new(P);
        // 0.3 m/s towards a wall 3 m ahead: the range closes exactly as fast as the robot drives.
        for k in 0..20 {
            let t = 0.15 * k as f64;
            assert_eq!(a.on_odometry(&odo(t, 0.3 * t, true, 1)), None);
            assert_eq!(a.on_ring(&ring(t, (3.0 - 0.3 * t) as f32, 2.0, 2.0)), None, "at {t} s");
        }
        assert_eq!(a.episodes, 0);
    }

    #[test]
    fn quantised_readings_a_lagging_odometry_and_a_turn_are_no_approach() {
        let mut a = PanicAvoid::new(P);
        let tenth_ft = |m: f64| ((m / 0.03048).round() * 0.03048) as f32;
        // Driving at 0.3 m/s at a wall 2.5 m ahead, readings in tenths of a foot, odometry one
        // 50 ms tick behind them.
        for k in 0..30 {
            let t = 0.05 * k as f64;
            a.on_odometry(&odo(t - 0.05, 0.3 * (t - 0.05).max(0.0), true, 1));
            if k % 3 == 0 {
                assert_eq!(a.on_ring(&ring(t, tenth_ft(2.5 - 0.3 * t), 2.0, 2.0)), None, "at {t} s");
            }
        }
        // Turning on the spot: the forward sensor sweeps from a far wall onto a near one.
        for k in 0..30 {
            let t = 2.0 + 0.15 * k as f64;
            let mut o = odo(t, 0.0, true, 2);
            o.world_from_robot.heading_rad = 0.5 * (t - 2.0);
            a.on_odometry(&o);
            let ahead = if k < 10 { 6.0 - 0.4 * k as f32 } else { 1.5 };
            assert_eq!(a.on_ring(&ring(t, ahead, 2.0, 2.0)), None, "turning, at {t} s");
        }
        assert_eq!(a.episodes, 0);
    }

    #[test]
    fn a_range_that_jumps_to_another_surface_is_no_approach() {
        let mut a = PanicAvoid::new(P);
        // Backing away from a room's corner: the forward beam slides off one wall onto the
        // other, and its range drops by a metre between two readings, then keeps growing.
        for k in 0..20 {
            let t = 0.15 * k as f64;
            a.on_odometry(&odo(t, -0.3 * t, true, 1));
            let ahead = if k < 8 { 3.0 + 0.3 * t } else { 2.0 + 0.3 * t };
            assert_eq!(a.on_ring(&ring(t, ahead as f32, 2.0, 2.0)), None, "at {t} s");
        }
        assert_eq!(a.episodes, 0);
    }

    #[test]
    fn a_small_turn_far_from_the_origin_is_no_approach() {
        let mut a = PanicAvoid::new(P);
        // 12 m from the world's origin and facing across that line, standing, then turning 1
        // degree (under the turn that restarts a window): every range stays the same.
        for k in 0..20 {
            let t = 0.15 * k as f64;
            let mut o = odo(t, 12.0, k == 6, 1);
            o.world_from_robot.heading_rad = if k < 6 { 90f64 } else { 91f64 }.to_radians();
            a.on_odometry(&o);
            assert_eq!(a.on_ring(&ring(t, 1.2, 2.0, 2.0)), None, "at {t} s");
        }
        assert_eq!(a.episodes, 0);
    }

    #[test]
    fn an_object_bearing_down_makes_the_robot_stop_turn_to_the_clear_side_and_dash() {
        let mut a = PanicAvoid::new(P);
        // The robot stands still; something comes at it at 0.6 m/s from 5 m; more room on the right.
        let mut stop = None;
        let mut k = 0;
        while stop.is_none() {
            let t = 0.15 * k as f64;
            a.on_odometry(&odo(t, 0.0, false, 7));
            stop = a.on_ring(&ring(t, (5.0 - 0.6 * t) as f32, 1.0, 4.0));
            k += 1;
            assert!(k < 40, "never fired");
        }
        let stop = stop.expect("fired");
        assert_eq!((stop.kind(), stop.urgent), (Some(CommandKind::Stop), 1));
        // Time to contact under 4 s (2.4 m at 0.6 m/s), confirmed by 3 readings after the first.
        let t = 0.15 * (k - 1) as f64;
        let range = 5.0 - 0.6 * t;
        assert!(range <= 2.4 && range > 2.4 - 3.0 * 0.09 - 1e-6, "fired at {range} m");
        assert!(a.evading());
        // Still: turn right (negative), a right angle, urgent, with a reflex id.
        let turn = a.on_odometry(&odo(t + 0.05, 0.0, false, 7)).expect("turns");
        assert_eq!((turn.kind(), turn.urgent), (Some(CommandKind::Turn), 1));
        assert!((turn.angle_rad + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!(turn.command_id & ID_BASE != 0);
        // Nothing more while it turns; the dash once the turn is done.
        assert_eq!(a.on_odometry(&odo(t + 0.5, 0.0, true, turn.command_id)), None);
        let dash = a.on_odometry(&odo(t + 2.0, 0.0, false, turn.command_id)).expect("dashes");
        assert_eq!((dash.kind(), dash.distance_m, dash.urgent), (Some(CommandKind::Move), 0.9, 1));
        // The object goes on by: the readings stop closing, and the evasion ends after the dash.
        a.on_ring(&ring(t + 2.1, 8.0, 1.0, 4.0));
        a.on_ring(&ring(t + 2.25, 8.0, 1.0, 4.0));
        assert_eq!(a.on_odometry(&odo(t + 4.0, 0.9, false, dash.command_id)), None);
        assert!(!a.evading());
        assert_eq!(a.episodes, 1);
    }

    #[test]
    fn a_spurious_reading_or_a_slow_drift_does_not_trigger() {
        let mut a = PanicAvoid::new(P);
        let ranges = [3.0, 3.0, 1.5, 3.0, 3.0, 2.98, 2.96, 2.94, 2.92, 2.90];
        for (k, &r) in ranges.iter().enumerate() {
            let t = 0.15 * k as f64;
            a.on_odometry(&odo(t, 0.0, false, 1));
            assert_eq!(a.on_ring(&ring(t, r, 2.0, 2.0)), None, "reading {k}");
        }
        assert_eq!(a.episodes, 0);
    }

    #[test]
    fn a_refused_turn_is_sent_again() {
        let mut a = PanicAvoid::new(P);
        let mut k = 0;
        while !a.evading() {
            let t = 0.15 * k as f64;
            a.on_odometry(&odo(t, 0.0, false, 7));
            a.on_ring(&ring(t, (3.0 - 0.6 * t) as f32, 4.0, 1.0));
            k += 1;
            assert!(k < 20, "never fired");
        }
        let turn = a.on_odometry(&odo(2.0, 0.0, false, 7)).expect("turns");
        assert!(turn.angle_rad > 0.0, "left is clearer");
        assert_eq!(a.on_odometry(&odo(2.5, 0.0, false, 7)), None, "give it time");
        let again = a.on_odometry(&odo(3.1, 0.0, false, 7)).expect("sent again");
        assert_eq!(again.kind(), Some(CommandKind::Turn));
        assert_ne!(again.command_id, turn.command_id);
    }
}
