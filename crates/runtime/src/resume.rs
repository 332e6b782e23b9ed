//! A service's resumption after a restart: its state as of the last finished tick, the newest
//! input it had taken from each topic, and the newest output it had sent on each, kept in its
//! [`Checkpoint`].
//!
//! A restarted subscriber is handed the newest messages again (the topics' history), and a
//! restarted service recomputes the tick it was killed in from the state before it: inputs at
//! or before what the state has taken are dropped ([`Resume::fresh`]), outputs at or before
//! what was sent are not sent twice ([`Resume::send_due`]). The state and its inputs are
//! saved together at tick boundaries ([`Resume::tick_done`]); the sent marks at every send.

use std::collections::BTreeMap;

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::checkpoint::{Checkpoint, CheckpointError};

/// (stamp, seq) of a message: the order a topic's messages come in.
type Mark = (u64, u64);

/// What the checkpoint holds: the state and its inputs as of the last tick boundary (encoded),
/// and the outputs sent since.
#[derive(Serialize, serde::Deserialize)]
struct Saved {
    committed: Vec<u8>,
    sent: BTreeMap<String, Mark>,
}

/// A service's state with what it has taken and sent.
pub struct Resume<S> {
    checkpoint: Option<Checkpoint>,
    state: S,
    taken: BTreeMap<String, Mark>,
    sent: BTreeMap<String, Mark>,
    /// The state and its inputs as of the last tick boundary, encoded.
    committed: Vec<u8>,
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
        let saved = checkpoint.as_mut().map(|c| c.load::<Saved>()).transpose()?.flatten();
        let Some(saved) = saved else {
            let mut r = Self {
                checkpoint,
                state: fresh(),
                taken: BTreeMap::new(),
                sent: BTreeMap::new(),
                committed: Vec::new(),
                resumed: false,
            };
            r.commit()?;
            return Ok(r);
        };
        let (state, taken): (S, BTreeMap<String, Mark>) =
            postcard::from_bytes(&saved.committed).map_err(|e| CheckpointError::Encoding {
                path: "state".into(),
                what: format!("reading the state: {e}"),
            })?;
        Ok(Self { checkpoint, state, taken, sent: saved.sent, committed: saved.committed, resumed: true })
    }

    /// Whether the state came from a checkpoint.
    pub fn resumed(&self) -> bool {
        self.resumed
    }

    pub fn state(&mut self) -> &mut S {
        &mut self.state
    }

    /// Whether an input on `topic` is news to the state (and notes it taken).
    pub fn fresh(&mut self, topic: &str, stamp_ns: u64, seq: u64) -> bool {
        newer(&mut self.taken, topic, (stamp_ns, seq))
    }

    /// Whether an output on `topic` still has to go out; notes it sent. A resumed service's
    /// recomputed outputs carry the same stamps and numbers as the ones its predecessor sent.
    pub fn send_due(&mut self, topic: &str, stamp_ns: u64, seq: u64) -> Result<bool, CheckpointError> {
        if !newer(&mut self.sent, topic, (stamp_ns, seq)) {
            return Ok(false);
        }
        self.save_sent()?;
        Ok(true)
    }

    /// The tick is finished: the state and what it has taken are saved.
    pub fn tick_done(&mut self) -> Result<(), CheckpointError> {
        if self.checkpoint.is_none() {
            return Ok(());
        }
        self.commit()?;
        self.save_sent()
    }

    fn commit(&mut self) -> Result<(), CheckpointError> {
        if self.checkpoint.is_some() {
            self.committed = postcard::to_allocvec(&(&self.state, &self.taken)).map_err(|e| {
                CheckpointError::Encoding { path: "state".into(), what: format!("writing the state: {e}") }
            })?;
        }
        Ok(())
    }

    fn save_sent(&mut self) -> Result<(), CheckpointError> {
        let Some(c) = self.checkpoint.as_mut() else { return Ok(()) };
        c.save(&Saved { committed: self.committed.clone(), sent: self.sent.clone() })
    }
}

fn newer(marks: &mut BTreeMap<String, Mark>, topic: &str, m: Mark) -> bool {
    match marks.get_mut(topic) {
        Some(last) if m <= *last => false,
        Some(last) => {
            *last = m;
            true
        }
        None => {
            marks.insert(topic.to_owned(), m);
            true
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

    /// A service that sums its inputs and sends the sum each tick, killed mid-tick.
    #[test]
    fn a_tick_cut_short_is_recomputed_from_the_state_before_it_and_sent_once() {
        let path = file("mid-tick");
        let open = || Resume::with(Some(Checkpoint::open(&path, 4096).unwrap()), || 0u64).unwrap();
        let mut r = open();
        assert!(!r.resumed());
        for t in 1..=3u64 {
            assert!(r.fresh("in", t, t));
            *r.state() += t;
            assert!(r.send_due("out", t, t).unwrap());
            r.tick_done().unwrap();
        }
        // Tick 4: its input taken and its output sent, then SIGKILL before the tick ends.
        assert!(r.fresh("in", 4, 4));
        *r.state() += 4;
        assert!(r.send_due("out", 4, 4).unwrap());
        drop(r);
        let mut again = open();
        assert!(again.resumed());
        assert_eq!(*again.state(), 6, "the state as the last finished tick left it");
        // The topic's history hands over tick 3's input (old news) and tick 4's (not yet taken).
        assert!(!again.fresh("in", 3, 3));
        assert!(again.fresh("in", 4, 4));
        *again.state() += 4;
        assert!(!again.send_due("out", 4, 4).unwrap(), "tick 4's output went out before the kill");
        again.tick_done().unwrap();
        assert!(again.fresh("in", 5, 5));
        assert!(again.send_due("out", 5, 5).unwrap());
        assert_eq!(*again.state(), 10);
    }
}
