//! Repeated warnings said once per period of message time, with how often they recurred: a
//! service that refuses the same input every frame (a false match the camera keeps making)
//! logs it when it starts, then once a period at most, then a count when it stops, instead of a
//! line per frame. Time is the messages' stamps, not the wall clock, so a replay logs the same
//! lines; the state is serialisable, so a restarted service keeps it in its checkpoint and logs
//! what it would have logged unrestarted.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// One warning's last saying, its last raising, and the repeats held back since it was said.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Said {
    at_ns: u64,
    last_ns: u64,
    held: u64,
}

/// The warnings said in the last period, by their text.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Throttle {
    period_ns: u64,
    said: BTreeMap<String, Said>,
}

/// A warning to say now.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Say {
    /// The warning itself, with the repeats held back since it was last said (0 the first time).
    Line { text: String, held: u64 },
    /// A warning that stopped recurring: its repeats held back after it was last said.
    Stopped { text: String, held: u64 },
}

impl std::fmt::Display for Say {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Say::Line { text, held: 0 } => write!(f, "{text}"),
            Say::Line { text, held } => write!(f, "{text} (and {held} more like it since it was last said)"),
            Say::Stopped { text, held } => write!(f, "{text} (repeated {held} more times, then stopped)"),
        }
    }
}

impl Throttle {
    /// Says a warning at most once per `period_ns` of message time.
    pub fn new(period_ns: u64) -> Self {
        Self { period_ns, said: BTreeMap::new() }
    }

    /// The warning `text`, raised at `stamp_ns`: `Some` to say it now, `None` to hold it back.
    pub fn raise(&mut self, text: String, stamp_ns: u64) -> Option<Say> {
        match self.said.get_mut(&text) {
            Some(s) if stamp_ns < s.at_ns.saturating_add(self.period_ns) => {
                s.held += 1;
                s.last_ns = s.last_ns.max(stamp_ns);
                None
            }
            Some(s) => {
                let held = std::mem::take(&mut s.held);
                (s.at_ns, s.last_ns) = (stamp_ns, stamp_ns);
                Some(Say::Line { text, held })
            }
            None => {
                self.said.insert(text.clone(), Said { at_ns: stamp_ns, last_ns: stamp_ns, held: 0 });
                Some(Say::Line { text, held: 0 })
            }
        }
    }

    /// The warnings not raised for a whole period by `now_ns`, forgotten; those with repeats
    /// held back come out as [`Say::Stopped`], in text order. A warning still recurring is
    /// kept (its stamps may lag `now_ns`: a sighting is taken a tick after its frame).
    pub fn expire(&mut self, now_ns: u64) -> Vec<Say> {
        let period = self.period_ns;
        let mut out = Vec::new();
        self.said.retain(|text, s| {
            let live = now_ns < s.last_ns.saturating_add(period);
            if !live && s.held > 0 {
                out.push(Say::Stopped { text: text.clone(), held: s.held });
            }
            live
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: u64 = 1_000_000_000;

    fn said(t: &mut Throttle, text: &str, at: u64) -> Option<String> {
        t.raise(text.to_owned(), at).map(|s| s.to_string())
    }

    #[test]
    fn a_warning_raised_every_frame_is_said_once_a_period_with_its_count() {
        let mut t = Throttle::new(5 * S);
        let mut lines = Vec::new();
        // Ten frames a second for 12 s.
        for k in 0..120u64 {
            let at = k * S / 10;
            lines.extend(said(&mut t, "rejected: corner", at));
            lines.extend(t.expire(at).iter().map(Say::to_string));
        }
        assert_eq!(
            lines,
            [
                "rejected: corner",
                "rejected: corner (and 49 more like it since it was last said)",
                "rejected: corner (and 49 more like it since it was last said)",
            ]
        );
        // It stops at 11.9 s: a period later, the 19 repeats since 10 s are counted, then it is
        // forgotten.
        assert!(t.expire(16 * S).is_empty());
        assert_eq!(
            t.expire(17 * S).iter().map(Say::to_string).collect::<Vec<_>>(),
            ["rejected: corner (repeated 19 more times, then stopped)"]
        );
        assert!(t.expire(18 * S).is_empty());
        assert_eq!(said(&mut t, "rejected: corner", 18 * S).as_deref(), Some("rejected: corner"));
    }

    #[test]
    fn different_warnings_are_counted_apart_and_a_lone_one_leaves_no_summary() {
        let mut t = Throttle::new(5 * S);
        assert!(said(&mut t, "a", 0).is_some());
        assert!(said(&mut t, "b", S).is_some());
        assert!(said(&mut t, "a", 2 * S).is_none());
        // "b" was said once and never again: forgotten without a line; "a" is still recurring.
        assert!(t.expire(6 * S).is_empty());
        assert!(said(&mut t, "b", 6 * S).is_some(), "forgotten, so said anew");
        assert_eq!(t.expire(7 * S), [Say::Stopped { text: "a".into(), held: 1 }]);
        assert!(said(&mut t, "a", 7 * S).is_some());
    }

    #[test]
    fn a_flood_whose_stamps_lag_the_tick_is_not_reported_stopped_while_it_goes_on() {
        // Sightings are stamped with their frame and applied when their odometry has come,
        // here 150 ms later: past the period's end before the next frame is raised.
        let mut t = Throttle::new(5 * S);
        let mut lines = Vec::new();
        for k in 1..=240u64 {
            let frame = k * S / 10;
            lines.extend(said(&mut t, "rejected: jamb", frame));
            lines.extend(t.expire(frame + 3 * S / 20).iter().map(Say::to_string));
        }
        assert_eq!(lines.len(), 5, "{lines:?}");
        assert!(lines.iter().all(|l| !l.contains("stopped")), "{lines:?}");
    }

    #[test]
    fn the_state_survives_a_checkpoint_round_trip() {
        let mut t = Throttle::new(5 * S);
        said(&mut t, "a", 0);
        said(&mut t, "a", S);
        let bytes = postcard::to_allocvec(&t).expect("encodes");
        let back: Throttle = postcard::from_bytes(&bytes).expect("decodes");
        assert_eq!(back, t);
    }
}
