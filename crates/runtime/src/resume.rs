//! A service's resumption after a restart: its state as of the last finished tick and the
//! newest input it had taken from each topic, kept in its [`Checkpoint`].
//!
//! A restarted party recomputes the tick it was killed in from the state before it. Its
//! subscribers are handed each topic's newest messages again (the supervisor has every
//! publisher re-offer its history first); inputs at or before what the state has taken are
//! dropped ([`Resume::fresh`]). The state and its inputs are saved together at tick
//! boundaries ([`Resume::tick_done`]), before the tick is reported done. What it sends is noted
//! as it goes ([`Sent`]): a killed publisher's samples still reach their subscribers, so a
//! recomputed output its predecessor had sent does not go out again.

use std::collections::BTreeMap;

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::checkpoint::{Checkpoint, CheckpointError};

/// (stamp, seq) of a message: the order a topic's messages come in.
type Mark = (u64, u64);

/// The newest (stamp, seq) taken from each topic: what a restarted service is handed again
/// and must drop. A topic's messages are taken to come in (stamp, seq) order (one publisher per
/// topic, or publishers that stamp apart).
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Marks(BTreeMap<String, Mark>);

impl Marks {
    /// Whether a message on `topic` is at or before the newest noted.
    pub fn seen(&self, topic: &str, stamp_ns: u64, seq: u64) -> bool {
        self.0.get(topic).is_some_and(|last| (stamp_ns, seq) <= *last)
    }

    /// Whether a message on `topic` is news (and notes it taken).
    pub fn fresh(&mut self, topic: &str, stamp_ns: u64, seq: u64) -> bool {
        let m = (stamp_ns, seq);
        match self.0.get_mut(topic) {
            Some(last) if m <= *last => false,
            Some(last) => {
                *last = m;
                true
            }
            None => {
                self.0.insert(topic.to_owned(), m);
                true
            }
        }
    }
}

/// A service's state with what it has taken.
pub struct Resume<S> {
    checkpoint: Option<Checkpoint>,
    state: S,
    taken: Marks,
    resumed: bool,
}

impl<S: Serialize + DeserializeOwned> Resume<S> {
    /// The state a predecessor of this service left in the supervisor's state folder, else
    /// `fresh()`. A service started by hand keeps no checkpoint.
    pub fn from_env(
        service: &str,
        slot_bytes: usize,
        fresh: impl FnOnce() -> S,
    ) -> Result<Self, CheckpointError> {
        Self::with(Checkpoint::from_env(service, slot_bytes)?, fresh)
    }

    pub fn with(
        mut checkpoint: Option<Checkpoint>,
        fresh: impl FnOnce() -> S,
    ) -> Result<Self, CheckpointError> {
        let saved = checkpoint.as_mut().map(|c| c.load::<(S, Marks)>()).transpose()?.flatten();
        Ok(match saved {
            Some((state, taken)) => Self { checkpoint, state, taken, resumed: true },
            None => Self { checkpoint, state: fresh(), taken: Marks::default(), resumed: false },
        })
    }

    /// Whether the state came from a checkpoint.
    pub fn resumed(&self) -> bool {
        self.resumed
    }

    pub fn state(&mut self) -> &mut S {
        &mut self.state
    }

    /// The state and what it has taken, apart (a runner hands the marks to a node's turn).
    pub fn parts(&mut self) -> (&mut S, &mut Marks) {
        (&mut self.state, &mut self.taken)
    }

    /// Whether a checkpoint is kept (the supervisor gave a state folder).
    pub fn keeps(&self) -> bool {
        self.checkpoint.is_some()
    }

    /// Whether an input on `topic` is news to the state (and notes it taken).
    pub fn fresh(&mut self, topic: &str, stamp_ns: u64, seq: u64) -> bool {
        self.taken.fresh(topic, stamp_ns, seq)
    }

    /// The tick is finished: the state and what it has taken are saved.
    pub fn tick_done(&mut self) -> Result<(), CheckpointError> {
        match self.checkpoint.as_mut() {
            Some(c) => c.save(&(&self.state, &self.taken)),
            None => Ok(()),
        }
    }
}

/// What a service has sent on each topic, saved as each message goes: a restarted party
/// recomputes the tick it was killed in, and what its predecessor had already sent of it (the
/// samples outlive their publisher) must not go out twice.
pub struct Sent {
    checkpoint: Option<Checkpoint>,
    marks: Marks,
}

impl Sent {
    /// The marks a predecessor of `service` left (`<service>-sent.ckpt`), else none.
    pub fn from_env(service: &str) -> Result<Self, CheckpointError> {
        let mut checkpoint = Checkpoint::from_env(&format!("{service}-sent"), 16 << 10)?;
        let marks = checkpoint.as_mut().map(|c| c.load::<Marks>()).transpose()?.flatten().unwrap_or_default();
        Ok(Self { checkpoint, marks })
    }

    /// No predecessor and no checkpoint (a node run in process).
    pub fn detached() -> Self {
        Self { checkpoint: None, marks: Marks::default() }
    }

    /// Whether a message on `topic` (or another key that numbers its own) still has to go out.
    pub fn due(&self, topic: &str, stamp_ns: u64, seq: u64) -> bool {
        !self.marks.seen(topic, stamp_ns, seq)
    }

    /// A message went out.
    pub fn done(&mut self, topic: &str, stamp_ns: u64, seq: u64) -> Result<(), CheckpointError> {
        self.marks.fresh(topic, stamp_ns, seq);
        match self.checkpoint.as_mut() {
            Some(c) => c.save(&self.marks),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("harvey-resume-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.ckpt");
        let _ = std::fs::remove_file(&path);
        path
    }

    /// A service that sums its inputs, killed mid-tick.
    #[test]
    fn a_tick_cut_short_is_recomputed_from_the_state_before_it() {
        let path = file("mid-tick");
        let open = || Resume::with(Some(Checkpoint::open(&path, 4096).unwrap()), || 0u64).unwrap();
        let mut r = open();
        assert!(!r.resumed());
        for t in 1..=3u64 {
            assert!(r.fresh("in", t, t));
            *r.state() += t;
            r.tick_done().unwrap();
        }
        // Tick 4: its input taken, then SIGKILL before the tick ends.
        assert!(r.fresh("in", 4, 4));
        *r.state() += 4;
        drop(r);
        let mut again = open();
        assert!(again.resumed());
        assert_eq!(*again.state(), 6, "the state as the last finished tick left it");
        // The topic's history hands over tick 3's input (old news) and tick 4's (not yet taken).
        assert!(!again.fresh("in", 3, 3));
        assert!(again.fresh("in", 4, 4));
        *again.state() += 4;
        again.tick_done().unwrap();
        assert!(again.fresh("in", 5, 5));
        assert_eq!(*again.state(), 10);
    }
}
