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
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
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

#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
enum Phase {
    Watching,
    /// Stop sent; waiting for the vehicle to be still.
    Stopping,
    Turning(Step),
    Dashing(Step),
    /// No room for another dash: the robot keeps still (an urgent stop every `HOLD_NS`) until
    /// the object stops approaching.
    Holding {
        sent_ns: u64,
    },
}

/// A turn or dash sent to the vehicle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
struct Step {
    id: u32,
    sent_ns: u64,
    /// The vehicle has moved since it was sent.
    moved: bool,
}

impl Step {
    /// Done: the vehicle, having moved on it, is still. Odometry names the newest command
    /// published, which during an evasion is often the executive's that the bridge refused, so
    /// the vehicle's motion, not the name, tells when the step is over.
    fn finished(&self, o: &Odometry) -> bool {
        let named = o.command.command_id == self.id && o.command_accepted == 1;
        o.moving == 0 && (self.moved || named)
    }

    /// Never run: the vehicle has not moved on it for this long (it refused the step).
    fn lost(&self, o: &Odometry) -> bool {
        let named = o.command.command_id == self.id;
        !self.moved && !named && o.moving == 0 && o.header.stamp_ns > self.sent_ns + RESEND_NS
    }
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
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct PanicAvoid {
    p: AvoidParams,
    approach: Approach,
    /// Set by the latest ring: some sensor (any bearing) confirmed an approach.
    approaching: bool,
    /// Clearance at the left and right (m) from the latest ring.
    clearance: [f64; 2],
    /// The nearest reading within the panic-stop's arc ahead (m).
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
        if let Phase::Turning(step) | Phase::Dashing(step) = &mut self.phase {
            step.moved |= self.moving;
        }
        let turn = self.away * self.p.turn_rad;
        match self.phase {
            // Away from the object (left is a positive turn).
            // No room to dash that way (a hall's wall): turning would leave the robot facing
            // it, the panic-stop holding it there; it keeps still instead.
            Phase::Stopping if !self.moving && self.side_room() < MIN_DASH_M => Some(self.hold(t)),
            Phase::Stopping if !self.moving => Some(self.turn(t, turn)),
            Phase::Turning(step) if step.lost(o) => Some(self.turn(t, turn)),
            Phase::Dashing(step) if step.lost(o) => Some(self.dash(t, self.dash_room().max(0.0))),
            Phase::Turning(step) | Phase::Dashing(step) if step.finished(o) => {
                let first = matches!(self.phase, Phase::Turning(_));
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
        self.phase = Phase::Turning(Step { id: c.command_id, sent_ns: t, moved: false });
        c
    }

    /// How far a dash could go after the turn: the clearance on the side turned to.
    fn side_room(&self) -> f64 {
        let side = if self.away > 0.0 { self.clearance[0] } else { self.clearance[1] };
        (side - self.p.stop_m - DASH_MARGIN_M).min(self.p.dash_m)
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
        self.phase = Phase::Dashing(Step { id: c.command_id, sent_ns: t, moved: false });
        c
    }

    /// Folds in a ring; returns the urgent stop that starts an evasion.
    pub fn on_ring(&mut self, ring: &SonarRing) -> Option<MotionCommand> {
        self.approach.on_ring(ring);
        let confirmed = |i: usize| self.approach.streak(i) >= self.p.confirm;
        // "Until no sensor senses the object approaching" (001 §6.2), on the evidence that
        // starts an evasion: several confirming readings of one sensor. A single reading closing
        // somewhere on the ring is not that: with 3 cm of range noise one of 24 sensors shows
        // one on most rings, and the robot dashed again after every dash.
        self.approaching = (0..SONAR_SENSORS).any(confirmed);
        let trigger = (0..SONAR_SENSORS).any(|i| {
            let b = bearing_rad(i);
            b.min(std::f64::consts::TAU - b) <= self.p.arc_rad && confirmed(i)
        });
        let side = |i: usize| {
            if ring.valid_mask & (1 << i) != 0 { f64::from(ring.range_m[i]) } else { f64::INFINITY }
        };
        let quarter = SONAR_SENSORS / 4;
        self.clearance = [side(quarter), side(3 * quarter)];
        // What the panic-stop watches (within 30 degrees of ahead): a dash longer than the
        // nearest of it allows is cut short by the panic-stop, and another dash sent after it.
        self.ahead_m =
            (0..SONAR_SENSORS).filter(|&i| crate::watched_ahead(i)).map(side).fold(f64::INFINITY, f64::min);
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
mod noise_tests;
#[cfg(test)]
mod tests;
