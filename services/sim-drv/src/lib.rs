//! The simulated Denning DRV: a pure state machine that accepts DRV commands, moves through the
//! world with the terrain error model, and produces what a DRV reports (shaft encoders and sonar
//! banks, in the DRV's units), plus the true pose for the simulator's own topic.
//!
//! [`drive::Drive`] runs it on a line, tick by tick; `main.rs` puts that on a pseudo-terminal
//! and paces it; nothing here reads a clock.

mod args;
pub mod drive;
pub mod motion;
pub mod sonar;
pub mod watchdog;

pub use args::Args;
use harvey_drv_protocol::{Command, NakReason, Report};
use harvey_world::World;

use harvey_geometry::Rng;
use motion::{FT, Motion, Pose2};

/// Longest MOVE the DRV accepts, in feet.
pub const MAX_MOVE_FT: f64 = 100.0;
/// Largest TURN the DRV accepts, in degrees.
pub const MAX_TURN_DEG: f64 = 360.0;

/// What one tick produces.
#[derive(Debug, Clone, PartialEq)]
pub struct TickOutput {
    pub time_ms: u64,
    pub truth: Pose2,
    pub reports: Vec<Report>,
}

/// Seeds the sensors' randomness apart from the motion's.
const SENSOR_STREAM: u64 = 0x0073_6f6e_6172;

/// Everything of the vehicle that changes as it runs (the world is rebuilt from its file and
/// seed): what a checkpoint keeps, so that a restarted simulator goes on with the same robot
/// rather than a fresh one at the start (the physics do not reset).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimState {
    rng: Rng,
    sensor_rng: Rng,
    time_ms: u64,
    truth: Pose2,
    encoders: Pose2,
    motion: Option<Motion>,
    last_command: u32,
    next_bank: u8,
    drift_sign: f64,
}

/// The simulated vehicle.
pub struct SimDrv {
    world: World,
    tick_ms: u64,
    s: SimState,
}

impl SimDrv {
    pub fn new(world: World, tick_ms: u64, seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        let drift_sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        let truth = world.start;
        let s = SimState {
            rng,
            sensor_rng: Rng::new(seed ^ SENSOR_STREAM),
            time_ms: 0,
            truth,
            encoders: truth,
            motion: None,
            last_command: 0,
            next_bank: 0,
            drift_sign,
        };
        Self { world, tick_ms, s }
    }

    /// The vehicle's state now.
    pub fn state(&self) -> SimState {
        self.s.clone()
    }

    /// Puts the vehicle back in a state [`SimDrv::state`] gave, in the same world.
    pub fn restore(&mut self, s: SimState) {
        self.world.set_time(s.time_ms as f64 / 1000.0);
        self.s = s;
    }

    pub fn truth(&self) -> Pose2 {
        self.s.truth
    }

    pub fn time_ms(&self) -> u64 {
        self.s.time_ms
    }

    pub fn is_moving(&self) -> bool {
        self.s.motion.is_some()
    }

    /// Abandons any motion at once, as the DRV's watchdog does (not a command: the last
    /// command's id stays in the reports).
    pub fn halt(&mut self) {
        self.s.motion = None;
    }

    /// Accepts or refuses a command; the answer goes back on the line at once.
    pub fn handle(&mut self, cmd: Command) -> Report {
        // The terrain under the robot when the command starts (its meadow's, 002 §4).
        let t = self.world.terrain_at(self.s.truth.x_m, self.s.truth.y_m).clone();
        let r = self.world.robot.clone();
        let (id, motion) = match cmd {
            Command::Stop { id } => {
                self.s.motion = None;
                (id, None)
            }
            Command::Move { id, hundredths_ft } => {
                let ft = f64::from(hundredths_ft) / 100.0;
                if ft.abs() > MAX_MOVE_FT {
                    return Report::Nak { id, reason: NakReason::OutOfRange };
                }
                if self.s.motion.is_some() {
                    return Report::Nak { id, reason: NakReason::Busy };
                }
                let m = motion::plan_move(
                    &t,
                    &mut self.s.rng,
                    self.s.drift_sign,
                    self.s.truth,
                    self.s.encoders,
                    ft * FT,
                    r.speed_mps,
                );
                (id, Some(m))
            }
            Command::Turn { id, tenths_deg } => {
                let deg = f64::from(tenths_deg) / 10.0;
                if deg.abs() > MAX_TURN_DEG {
                    return Report::Nak { id, reason: NakReason::OutOfRange };
                }
                if self.s.motion.is_some() {
                    return Report::Nak { id, reason: NakReason::Busy };
                }
                let rate = r.turn_rate_degps.to_radians();
                (
                    id,
                    Some(motion::plan_turn(
                        &t,
                        &mut self.s.rng,
                        self.s.truth,
                        self.s.encoders,
                        deg.to_radians(),
                        rate,
                    )),
                )
            }
            Command::Velocity { id, hundredths_ft_per_s, tenths_deg_per_s } => {
                let v = f64::from(hundredths_ft_per_s) / 100.0 * FT;
                let w = (f64::from(tenths_deg_per_s) / 10.0).to_radians();
                if v.abs() > r.speed_mps * 1.5 || w.abs() > r.turn_rate_degps.to_radians() * 1.5 {
                    return Report::Nak { id, reason: NakReason::OutOfRange };
                }
                let drift = self.s.drift_sign
                    * self.s.rng.normal(t.drift_deg_per_ft, t.drift_sd_deg_per_ft).to_radians()
                    / FT;
                let idle = v == 0.0 && w == 0.0;
                (id, (!idle).then_some(Motion::Velocity { v_mps: v, w_radps: w, drift_rad_per_m: drift }))
            }
        };
        self.s.motion = motion;
        self.s.last_command = id;
        Report::Ack { id }
    }

    /// Advances time by one tick: moves, fires the next sonar bank, reports encoders.
    pub fn tick(&mut self) -> TickOutput {
        self.s.time_ms += self.tick_ms;
        // Moving things are where their timetables put them now (no-op in a still world).
        self.world.set_time(self.s.time_ms as f64 / 1000.0);
        let dt_s = self.tick_ms as f64 / 1000.0;
        if let Some(m) = &mut self.s.motion {
            let t = self.world.terrain_at(self.s.truth.x_m, self.s.truth.y_m);
            let counts = motion::Counts::of(&self.world.robot);
            let (truth, enc, finished) = motion::advance(m, t, counts, self.s.truth, self.s.encoders, dt_s);
            self.s.truth = truth;
            self.s.encoders = enc;
            if finished {
                self.s.motion = None;
            }
        }
        let bank = self.s.next_bank;
        self.s.next_bank = (bank + 1) % 3;
        let ranges_tenths_ft = sonar::fire_bank(&self.world, self.s.truth, bank, &mut self.s.sensor_rng);
        let heading_deg = self.s.encoders.heading_rad.to_degrees().rem_euclid(360.0);
        let reports = vec![
            Report::Encoders {
                time_ms: self.s.time_ms,
                x_hundredths_ft: (self.s.encoders.x_m / FT * 100.0).round() as i32,
                y_hundredths_ft: (self.s.encoders.y_m / FT * 100.0).round() as i32,
                heading_tenths_deg: ((heading_deg * 10.0).round() as i32) % 3600,
                moving: self.s.motion.is_some(),
                command_id: self.s.last_command,
            },
            Report::Sonar { time_ms: self.s.time_ms, bank, ranges_tenths_ft },
        ];
        TickOutput { time_ms: self.s.time_ms, truth: self.s.truth, reports }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sim(seed: u64) -> SimDrv {
        let w =
            harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads");
        SimDrv::new(w, 50, seed)
    }

    #[test]
    fn a_move_runs_to_completion_and_reports_it() {
        let mut s = sim(3);
        assert_eq!(s.handle(Command::Move { id: 1, hundredths_ft: 1000 }), Report::Ack { id: 1 });
        assert_eq!(
            s.handle(Command::Move { id: 2, hundredths_ft: 1000 }),
            Report::Nak { id: 2, reason: NakReason::Busy }
        );
        let mut last = None;
        for _ in 0..400 {
            last = Some(s.tick());
            if !s.is_moving() {
                break;
            }
        }
        let out = last.expect("ticked");
        assert!(!s.is_moving());
        let Report::Encoders { x_hundredths_ft, moving, command_id, .. } = out.reports[0] else {
            panic!("{out:?}")
        };
        assert_eq!((x_hundredths_ft, moving, command_id), (1000, false, 1));
        let true_ft = out.truth.x_m / FT;
        assert!(true_ft < 10.0 && true_ft > 9.4, "{true_ft}");
    }

    #[test]
    fn impossible_commands_are_refused() {
        let mut s = sim(3);
        assert_eq!(
            s.handle(Command::Move { id: 5, hundredths_ft: 528_000 }),
            Report::Nak { id: 5, reason: NakReason::OutOfRange }
        );
        assert_eq!(
            s.handle(Command::Turn { id: 6, tenths_deg: 7200 }),
            Report::Nak { id: 6, reason: NakReason::OutOfRange }
        );
        assert!(!s.is_moving());
    }

    #[test]
    fn a_restored_vehicle_goes_on_as_the_original_would() {
        let mut a = sim(4);
        a.handle(Command::Move { id: 1, hundredths_ft: 800 });
        for _ in 0..37 {
            a.tick();
        }
        let saved = a.state();
        let mut b = sim(4);
        b.restore(saved.clone());
        assert_eq!(b.state(), saved);
        let ahead: Vec<_> = (0..200).map(|_| a.tick()).collect();
        let again: Vec<_> = (0..200).map(|_| b.tick()).collect();
        assert_eq!(ahead, again);
        // A fresh vehicle would not: it starts over at the world's start.
        let mut c = sim(4);
        assert_ne!(c.tick().truth, ahead[0].truth);
    }

    #[test]
    fn same_seed_same_run() {
        let run = |seed| {
            let mut s = sim(seed);
            s.handle(Command::Turn { id: 1, tenths_deg: 450 });
            (0..100).map(|_| s.tick()).collect::<Vec<_>>()
        };
        assert_eq!(run(9), run(9));
        assert_ne!(run(9), run(10));
    }
}
