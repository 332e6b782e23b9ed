//! A service's warnings and errors on `rosout`, deterministically: the WARN and ERROR events its
//! logic raises during a turn are captured and published stamped with the turn's tick, so they
//! are recorded (and replayed) like any other output.
//!
//! Capture is per thread and only between [`Rosout::begin`] and [`Rosout::end`]; events outside
//! a turn (start-up, "resumed from the checkpoint", shutdown) are not the run's and stay in the
//! supervisor's output only, as do events of the bus and runtime plumbing. Lines are numbered
//! per service; a restarted service that recomputes the tick it was killed in numbers its lines
//! from where that tick began and sends only those its predecessor had not (its samples outlive
//! it), so a SIGKILL leaves `rosout` as it would have been.

use std::cell::RefCell;
use std::fmt::Write as _;

use harvey_bus::{Bus, Publisher};
use harvey_msgs::{Header, LogLevel, LogLine, topics};
use serde::{Deserialize, Serialize};
use tracing::field::{Field, Visit};
use tracing::{Event, Level, Subscriber};
use tracing_subscriber::layer::{Context, Layer};

use crate::checkpoint::Checkpoint;

thread_local! {
    /// The lines captured in the current turn; `None` outside a turn.
    static CAPTURED: RefCell<Option<Vec<(LogLevel, String)>>> = const { RefCell::new(None) };
}

/// Targets whose events are plumbing, not a service's logic: never captured.
const PLUMBING: [&str; 2] = ["harvey_bus", "harvey_runtime"];

/// The tracing layer that captures WARN and ERROR events of Harvey's own code during a turn
/// ([`crate::init_logging`] installs it).
pub struct CaptureLayer;

impl<S: Subscriber> Layer<S> for CaptureLayer {
    fn on_event(&self, event: &Event<'_>, _ctx: Context<'_, S>) {
        let level = match *event.metadata().level() {
            Level::ERROR => LogLevel::Error,
            Level::WARN => LogLevel::Warn,
            _ => return,
        };
        let target = event.metadata().target();
        let crate_name = target.split("::").next().unwrap_or(target);
        if !crate_name.starts_with("harvey_") || PLUMBING.contains(&crate_name) {
            return;
        }
        CAPTURED.with(|c| {
            if let Some(lines) = c.borrow_mut().as_mut() {
                let mut text = Text::default();
                event.record(&mut text);
                lines.push((level, text.finish()));
            }
        });
    }
}

/// An event as one line: its message, then its fields as `key=value`.
#[derive(Default)]
struct Text {
    message: String,
    fields: String,
}

impl Text {
    fn finish(self) -> String {
        match (self.message.is_empty(), self.fields.is_empty()) {
            (_, true) => self.message,
            (true, false) => self.fields,
            (false, false) => format!("{} {}", self.message, self.fields),
        }
    }
}

impl Visit for Text {
    fn record_debug(&mut self, field: &Field, value: &dyn std::fmt::Debug) {
        if field.name() == "message" {
            let _ = write!(self.message, "{value:?}");
        } else {
            let sep = if self.fields.is_empty() { "" } else { " " };
            let _ = write!(self.fields, "{sep}{}={value:?}", field.name());
        }
    }
}

/// How a service's lines are numbered, saved whenever a line goes out.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
struct Numbering {
    /// The stamp of the last turn that sent a line, and the number its first line took.
    turn: Option<(u64, u64)>,
    /// The next line's number.
    next: u64,
    /// The newest line sent, (stamp, seq).
    sent: Option<(u64, u64)>,
}

impl Numbering {
    /// Numbers for a turn stamped `stamp`: a restarted service's first turn on the tick its
    /// predecessor had begun sending numbers from where that tick began.
    fn start(&mut self, stamp: u64, first_turn: bool) {
        match self.turn {
            Some((t, first)) if t == stamp && first_turn => self.next = first,
            Some((t, _)) if t == stamp => {}
            _ => self.turn = Some((stamp, self.next)),
        }
    }

    fn due(&self, stamp: u64, seq: u64) -> bool {
        self.sent.is_none_or(|s| (stamp, seq) > s)
    }
}

/// A service's `rosout` publisher.
pub struct Rosout {
    /// None: a node run in process, whose runner takes the lines ([`Rosout::end_with`]).
    port: Option<Publisher<LogLine>>,
    name: String,
    numbering: Numbering,
    checkpoint: Option<Checkpoint>,
    first_turn: bool,
    /// Lines captured before a [`Rosout::pause`], for the turn's end.
    held: Vec<(LogLevel, String)>,
}

impl Rosout {
    /// The publisher of service `name`, its numbering as a predecessor left it
    /// (`<name>-rosout.ckpt` in `$HARVEY_STATE_DIR`).
    pub fn new(bus: &Bus, name: &str) -> anyhow::Result<Self> {
        let mut checkpoint = Checkpoint::from_env(&format!("{name}-rosout"), 1024)?;
        let numbering =
            checkpoint.as_mut().map(|c| c.load::<Numbering>()).transpose()?.flatten().unwrap_or_default();
        let port = Some(bus.publisher(topics::ROSOUT)?);
        Ok(Self { port, name: name.to_owned(), numbering, checkpoint, first_turn: true, held: Vec::new() })
    }

    /// Service `name`'s lines for a runner that delivers them itself (in process): no bus, no
    /// checkpoint.
    pub fn detached(name: &str) -> Self {
        let numbering = Numbering::default();
        Self {
            port: None,
            name: name.to_owned(),
            numbering,
            checkpoint: None,
            first_turn: true,
            held: Vec::new(),
        }
    }

    /// A turn begins: this thread's WARN and ERROR events are captured from now on (what was
    /// captured since a `begin` that no `end` closed is kept).
    pub fn begin(&self) {
        CAPTURED.with(|c| {
            c.borrow_mut().get_or_insert_with(Vec::new);
        });
    }

    /// Capture stops until the next [`Rosout::begin`]; what was captured is kept for the turn's
    /// end (the bridge pauses while it reopens its line: plumbing, not the run's).
    pub fn pause(&mut self) {
        if let Some(lines) = CAPTURED.with(|c| c.borrow_mut().take()) {
            self.held.extend(lines);
        }
    }

    /// The turn ends: what was captured goes out stamped `stamp_ns` (the tick in deterministic
    /// mode; in real time the newest input the turn took). Returns the lines sent.
    pub fn end(&mut self, stamp_ns: u64) -> anyhow::Result<usize> {
        let port = self.port.take();
        let sent = self.end_with(stamp_ns, |line| {
            port.as_ref().map(|p| p.send(line)).transpose()?;
            Ok(())
        });
        self.port = port;
        sent
    }

    /// [`Rosout::end`], each line handed to `send` (a detached service's runner delivers them).
    pub fn end_with(
        &mut self,
        stamp_ns: u64,
        mut send: impl FnMut(&LogLine) -> anyhow::Result<()>,
    ) -> anyhow::Result<usize> {
        let mut lines = std::mem::take(&mut self.held);
        lines.extend(CAPTURED.with(|c| c.borrow_mut().take()).unwrap_or_default());
        let first_turn = std::mem::replace(&mut self.first_turn, false);
        if lines.is_empty() {
            return Ok(0);
        }
        self.numbering.start(stamp_ns, first_turn);
        let mut sent = 0;
        for (level, text) in lines {
            let seq = self.numbering.next;
            self.numbering.next += 1;
            if self.numbering.due(stamp_ns, seq) {
                send(&LogLine::new(Header::new(seq, stamp_ns), level, &self.name, &text))?;
                self.numbering.sent = Some((stamp_ns, seq));
                sent += 1;
            }
            if let Some(c) = self.checkpoint.as_mut() {
                c.save(&self.numbering)?;
            }
        }
        Ok(sent)
    }
}

/// Captures this thread's lines as a turn would, for tests of what a piece of logic logs.
pub fn capture(f: impl FnOnce()) -> Vec<(LogLevel, String)> {
    CAPTURED.with(|c| *c.borrow_mut() = Some(Vec::new()));
    f();
    CAPTURED.with(|c| c.borrow_mut().take()).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracing_subscriber::layer::SubscriberExt;

    #[test]
    fn only_warnings_and_errors_of_harvey_code_inside_a_turn_are_captured() {
        let subscriber = tracing_subscriber::registry().with(CaptureLayer);
        tracing::subscriber::with_default(subscriber, || {
            tracing::warn!(target: "harvey_ums", "outside a turn");
            let lines = capture(|| {
                tracing::warn!(target: "harvey_ums", kept = 1, why = "far", "rejected: too far");
                tracing::info!(target: "harvey_ums", "not a warning");
                tracing::error!(target: "harvey_executive::plan", "mission failed");
                tracing::warn!(target: "harvey_bus::reoffer", "plumbing");
                tracing::warn!(target: "iceoryx2", "another crate's");
            });
            assert_eq!(
                lines,
                vec![
                    (LogLevel::Warn, r#"rejected: too far kept=1 why="far""#.to_owned()),
                    (LogLevel::Error, "mission failed".to_owned()),
                ]
            );
            tracing::warn!(target: "harvey_ums", "after the turn");
            assert!(capture(|| {}).is_empty());
        });
    }

    #[test]
    fn a_recomputed_tick_numbers_its_lines_from_where_the_tick_began() {
        let mut n = Numbering::default();
        n.start(10, true);
        n.next += 2; // tick 10 sent lines 0 and 1
        n.sent = Some((10, 1));
        n.start(20, false);
        assert_eq!(n.turn, Some((20, 2)));
        n.next += 1; // line 2 sent at tick 20, then SIGKILL before the tick was done
        n.sent = Some((20, 2));
        // The successor recomputes tick 20: the same numbers, the sent one not again.
        let mut again = n;
        again.start(20, true);
        assert_eq!(again.next, 2);
        assert!(!again.due(20, 2));
        assert!(again.due(20, 3));
        // A real-time service's second turn with the same stamp goes on counting.
        let mut live = n;
        live.start(20, false);
        assert_eq!(live.next, 3);
    }
}
