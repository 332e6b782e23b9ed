//! What of the UMS changes as it runs, for its checkpoint: the map, the history late sightings
//! rewind to, the sightings waiting for their odometry and its counts. The world and the
//! configuration are rebuilt from the service's arguments, so a restarted UMS goes on with the
//! same uncertainty rather than one shrunk to the start's point.

use std::collections::VecDeque;

use harvey_msgs::LandmarkSighting;

use crate::map::Map;
use crate::{Step, Ums};

/// The UMS's state, apart from its world and configuration.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct UmsState {
    map: Map,
    history: VecDeque<(u64, Map, Step)>,
    pending: Vec<LandmarkSighting>,
    command_id: u32,
    travelled_m: f64,
    turned_rad: f64,
    run_started: bool,
    last_stamp_ns: u64,
    missed: u32,
    seq: u64,
    expectation_seq: u64,
    mount: crate::mount::Mount,
}

impl PartialEq for Step {
    fn eq(&self, o: &Self) -> bool {
        (self.turn_rad, self.run_m, self.first_run) == (o.turn_rad, o.run_m, o.first_run)
    }
}

impl Ums {
    /// The state now.
    pub fn state(&self) -> UmsState {
        UmsState {
            map: self.map.clone(),
            history: self.history.clone(),
            pending: self.pending.clone(),
            command_id: self.command_id,
            travelled_m: self.travelled_m,
            turned_rad: self.turned_rad,
            run_started: self.run_started,
            last_stamp_ns: self.last_stamp_ns,
            missed: self.missed,
            seq: self.seq,
            expectation_seq: self.expectation_seq,
            mount: self.mount.clone(),
        }
    }

    /// Puts back a state [`Ums::state`] gave, for the same world and configuration.
    pub fn restore(&mut self, s: UmsState) {
        (self.map, self.history, self.pending) = (s.map, s.history, s.pending);
        (self.command_id, self.travelled_m, self.turned_rad) = (s.command_id, s.travelled_m, s.turned_rad);
        (self.run_started, self.last_stamp_ns, self.missed) = (s.run_started, s.last_stamp_ns, s.missed);
        (self.seq, self.expectation_seq, self.mount) = (s.seq, s.expectation_seq, s.mount);
    }
}
