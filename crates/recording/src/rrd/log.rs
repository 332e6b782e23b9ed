//! The log a person reads and the state lanes: mission steps, its end, the servoing level and the
//! UMS losing and finding the robot at INFO or WARN, each under its source (`log/executive`,
//! `log/ums`, `log/sonar`); the sonar reflexes at WARN; the motion commands at DEBUG, and only when
//! they differ from the one before (the executive repeats its command every tick); velocity
//! commands, new every tick, as plots of speed and turn rate; the services' own warnings and
//! errors (`rosout`) under their service's name, a line repeated within a few seconds drawn
//! once with the count of its repeats (the MCAP keeps every one).

use harvey_msgs::{
    CommandKind, LogLevel, LogLine, MissionState, MissionStatus, MotionCommand, PANIC_STOP_IDS,
    REFLEX_ID_BIT, ServoLevel,
};
use rerun::TextLogLevel;

use super::{RrdError, RrdWriter};

/// What a command asks, in words; the id is left out so that repeats compare equal.
pub(super) fn describe(c: &MotionCommand) -> String {
    match c.kind() {
        Some(CommandKind::Stop) => "stop".to_owned(),
        Some(CommandKind::Move) => format!("move {:.3} m", c.distance_m),
        Some(CommandKind::Turn) => format!("turn {:.1} deg", c.angle_rad.to_degrees()),
        Some(CommandKind::Velocity) => {
            format!("velocity {:.3} m/s, {:.1} deg/s", c.linear_mps, c.angular_radps.to_degrees())
        }
        None => format!("kind {}", c.kind),
    }
}

/// A service's line repeated within this much simulated time is not drawn again.
const REPEAT_WINDOW_NS: u64 = 5_000_000_000;

/// The `rosout` lines drawn lately: (service, text) → (stamp drawn, repeats since).
#[derive(Default)]
pub(super) struct Repeats(std::collections::BTreeMap<(String, String), (u64, u32)>);

impl Repeats {
    /// Whether a line is drawn, and if so how many repeats of it were held back before it.
    fn admit(&mut self, source: &str, text: &str, stamp_ns: u64) -> Option<u32> {
        let key = (source.to_owned(), text.to_owned());
        match self.0.get_mut(&key) {
            Some((drawn, held)) if stamp_ns < *drawn + REPEAT_WINDOW_NS => {
                *held += 1;
                None
            }
            Some((drawn, held)) => {
                *drawn = stamp_ns;
                Some(std::mem::take(held))
            }
            None => {
                self.0.insert(key, (stamp_ns, 0));
                Some(0)
            }
        }
    }
}

fn servo_name(raw: u32) -> &'static str {
    ServoLevel::from_raw(raw).map_or("?", |l| match l {
        ServoLevel::None => "no servoing",
        ServoLevel::Action => "action-level servoing",
        ServoLevel::Plan => "plan-level servoing",
        ServoLevel::Goal => "goal-level servoing",
    })
}

impl RrdWriter {
    /// A line of the log under `log/<source>`, the source also leading the text (the entity
    /// column is narrow).
    pub(super) fn say(&self, source: &str, level: &str, text: String) -> Result<(), RrdError> {
        let line = rerun::TextLog::new(format!("{source}: {text}")).with_level(level);
        self.rec.log(format!("log/{source}"), &line).map_err(|e| self.err(e))
    }

    /// A lane of the state timeline under `states/<lane>`.
    pub(super) fn lane(&self, lane: &str, state: String) -> Result<(), RrdError> {
        self.rec.log(format!("states/{lane}"), &rerun::StateChange::single(state)).map_err(|e| self.err(e))
    }

    pub fn command(&mut self, c: &MotionCommand) -> Result<(), RrdError> {
        let reflex = c.command_id & REFLEX_ID_BIT != 0;
        if !reflex && c.kind() == Some(CommandKind::Velocity) {
            // Velocity commands change every tick: plotted, and logged when they begin.
            self.at(c.header.stamp_ns);
            let speed = rerun::Scalars::single(c.linear_mps);
            self.rec.log("plots/speed/linear_mps", &speed).map_err(|e| self.err(e))?;
            let turning = rerun::Scalars::single(c.angular_radps.to_degrees());
            self.rec.log("plots/turning/angular_degps", &turning).map_err(|e| self.err(e))?;
        }
        let what = match c.kind() {
            Some(CommandKind::Velocity) if !reflex => "velocity control".to_owned(),
            _ => describe(c),
        };
        let last = if reflex { &mut self.last_reflex } else { &mut self.last_command };
        if last.as_deref() == Some(what.as_str()) {
            return Ok(());
        }
        *last = Some(what.clone());
        self.at(c.header.stamp_ns);
        if reflex {
            let name =
                if c.command_id & PANIC_STOP_IDS == PANIC_STOP_IDS { "panic-stop" } else { "panic-avoid" };
            return self.say("sonar", TextLogLevel::WARN, format!("{name}: {what}"));
        }
        let urgent = if c.urgent != 0 { " (urgent)" } else { "" };
        self.say("commands", TextLogLevel::DEBUG, format!("command {}: {what}{urgent}", c.command_id))
    }

    /// The executive's status: its estimate as a path; its step, end and servoing level in the
    /// log and the lanes when they change.
    pub fn status(&mut self, s: &MissionStatus) -> Result<(), RrdError> {
        self.goal = Some(s.goal);
        self.at(s.header.stamp_ns);
        self.estimate(&s.estimated)?;
        let now = (s.state, s.step, s.servo);
        let before = self.last_state.replace(now);
        if before == Some(now) {
            return Ok(());
        }
        // A sequenced mission has no steps (its acceptor has the lane that tells).
        let steps = match s.step_count {
            0 => "running".to_owned(),
            n => format!("step {}/{n}", (s.step + 1).min(n)),
        };
        let (mission, level, text) = match s.state() {
            Some(MissionState::Running) => (steps.clone(), TextLogLevel::INFO, format!("{steps}: under way")),
            Some(MissionState::Succeeded) => {
                ("succeeded".to_owned(), TextLogLevel::INFO, "mission succeeded".into())
            }
            Some(MissionState::Failed) => {
                ("FAILED".to_owned(), TextLogLevel::ERROR, format!("mission FAILED at {steps}"))
            }
            None => (
                format!("state {}", s.state),
                TextLogLevel::WARN,
                format!("unknown mission state {}", s.state),
            ),
        };
        if before.is_none_or(|(state, step, _)| (state, step) != (s.state, s.step)) {
            self.say("executive", level, text)?;
            self.lane("mission", mission)?;
        }
        if before.is_none_or(|(_, _, servo)| servo != s.servo) {
            self.say("executive", TextLogLevel::INFO, format!("now {}", servo_name(s.servo)))?;
            self.lane("servoing", servo_name(s.servo).to_owned())?;
        }
        Ok(())
    }

    /// A service's own warning or error (`rosout`), under `log/<service>` at its level.
    pub fn rosout(&mut self, l: &LogLine) -> Result<(), RrdError> {
        let level = match l.level() {
            Some(LogLevel::Debug) => TextLogLevel::DEBUG,
            Some(LogLevel::Info) => TextLogLevel::INFO,
            Some(LogLevel::Warn) => TextLogLevel::WARN,
            Some(LogLevel::Error | LogLevel::Fatal) | None => TextLogLevel::ERROR,
        };
        let source = match l.name() {
            "" => "unnamed",
            name => name,
        };
        let Some(held) = self.repeats.admit(source, l.text(), l.header.stamp_ns) else {
            return Ok(());
        };
        let text = match held {
            0 => l.text().to_owned(),
            n => {
                format!("{} ({n} more like it in the last {} s)", l.text(), REPEAT_WINDOW_NS / 1_000_000_000)
            }
        };
        self.at(l.header.stamp_ns);
        self.say(source, level, text)
    }

    /// The UMS's map holding the robot or lost, logged and laned when it changes.
    pub(super) fn ums_state(&mut self, lost: bool) -> Result<(), RrdError> {
        if self.lost == Some(lost) {
            return Ok(());
        }
        let first = self.lost.is_none();
        self.lost = Some(lost);
        self.lane("ums", if lost { "lost".into() } else { "localised".into() })?;
        match (lost, first) {
            (true, _) => {
                self.say("ums", TextLogLevel::WARN, "lost: the map no longer holds the robot".into())
            }
            (false, false) => {
                self.say("ums", TextLogLevel::INFO, "relocated: the map holds the robot again".into())
            }
            (false, true) => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_repeated_line_is_drawn_once_per_window_with_its_count() {
        let mut r = Repeats::default();
        let s = 1_000_000_000;
        assert_eq!(r.admit("ums", "rejected: x", 0), Some(0));
        assert_eq!(r.admit("ums", "rejected: x", s), None);
        assert_eq!(r.admit("ums", "rejected: y", s), Some(0), "another text is drawn");
        assert_eq!(r.admit("executive", "rejected: x", s), Some(0), "another service is drawn");
        assert_eq!(r.admit("ums", "rejected: x", 4 * s), None);
        assert_eq!(r.admit("ums", "rejected: x", 5 * s), Some(2), "drawn again, with the two held back");
        assert_eq!(r.admit("ums", "rejected: x", 6 * s), None);
    }

    #[test]
    fn a_command_reads_as_what_it_asks_whatever_its_id() {
        let mut c = MotionCommand {
            kind: CommandKind::Move as u32,
            distance_m: 1.2345,
            command_id: 7,
            ..Default::default()
        };
        assert_eq!(describe(&c), "move 1.234 m");
        c.command_id = 8;
        assert_eq!(describe(&c), "move 1.234 m", "a repeat with a new id reads the same");
        c.kind = CommandKind::Turn as u32;
        c.angle_rad = std::f64::consts::PI;
        assert_eq!(describe(&c), "turn 180.0 deg");
        c.kind = 9;
        assert_eq!(describe(&c), "kind 9");
    }
}
