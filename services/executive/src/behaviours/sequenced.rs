//! What every acceptor-sequenced behaviour (004 §3) shares: the finite state acceptor and its
//! triggers, the one vision request awaited at a time, and each tick's velocity command and
//! published state (the acceptor's state and the motor schemas' vectors).

use harvey_msgs::{
    BehaviourState, Header, MotionCommand, Pose2, VisionAlgorithm, VisionRequest, VisionResult,
};

use super::drive::{self, Vectors};
use super::fsa::{Fsa, Trigger};

/// The acceptor and the request and command bookkeeping.
#[derive(Debug, Clone)]
pub struct Sequenced {
    pub fsa: Fsa,
    pending: Option<u32>,
    next_request: u32,
    last_trigger: Trigger,
    next_id: u32,
    seq: u64,
}

impl Sequenced {
    pub fn new(fsa: Fsa) -> Self {
        Self { fsa, pending: None, next_request: 1000, last_trigger: Trigger::Normal, next_id: 1, seq: 0 }
    }

    /// The perceptual algorithm of the state it is in.
    pub fn perception(&self) -> &str {
        self.fsa.state().perception.as_deref().unwrap_or("")
    }

    /// Takes a trigger (one the acceptor has no transition for leaves it where it is).
    pub fn trigger(&mut self, t: Trigger) {
        let from = self.fsa.state().name.clone();
        if let Ok(to) = self.fsa.step(t) {
            if to.name != from {
                tracing::info!(from = %from, to = %to.name, trigger = ?t, "acceptor transition");
            }
            self.last_trigger = t;
        }
    }

    /// Whether a request is awaited.
    pub fn waiting(&self) -> bool {
        self.pending.is_some()
    }

    /// Forgets the request awaited (its answer will be ignored).
    pub fn forget(&mut self) {
        self.pending = None;
    }

    /// A request, now awaited.
    pub fn request(
        &mut self,
        stamp_ns: u64,
        algorithm: VisionAlgorithm,
        window: [f32; 4],
        params: [f32; 8],
    ) -> VisionRequest {
        let id = self.next_request;
        self.next_request += 1;
        self.pending = Some(id);
        VisionRequest {
            header: Header::new(u64::from(id), stamp_ns),
            request_id: id,
            algorithm: algorithm as u32,
            window_px: window,
            params,
            ..VisionRequest::default()
        }
    }

    /// Whether `r` answers the request awaited (then no longer awaited).
    pub fn answers(&mut self, r: &VisionResult) -> bool {
        let ours = self.pending == Some(r.request_id);
        if ours {
            self.pending = None;
        }
        ours
    }

    /// This tick's velocity command and published state.
    pub fn output(
        &mut self,
        at: Pose2,
        now: u64,
        vectors: &Vectors,
        (v, w): (f64, f64),
        achieved: u32,
    ) -> (MotionCommand, BehaviourState) {
        let id = self.next_id;
        self.next_id += 1;
        self.seq += 1;
        let state = BehaviourState {
            header: Header::new(self.seq, now),
            at,
            fsa_state: self.fsa.trace.last().copied().unwrap_or(0) as u32,
            transitions: self.fsa.trace.len().saturating_sub(1) as u32,
            last_trigger: self.last_trigger as u32,
            achieved,
            vectors_mps: vectors.flat(),
            linear_mps: v,
            angular_radps: w,
        };
        (drive::command(id, now, (v, w)), state)
    }
}
