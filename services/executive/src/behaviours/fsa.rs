//! Perceptual sequencing by finite state acceptors (004 §3.1): `(Q, δ, q0, F)`, each state
//! naming the perceptual algorithm active in it, `δ` a table from the state and the kind of
//! trigger (normal, terminal, recoverable error, fatal error) to the next state. Acceptors are
//! data: loaded from TOML files (`missions/fsa/`), checked whole before use.

use serde::Deserialize;

/// An acceptor that cannot be used, or a trigger it has no transition for.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FsaError {
    #[error("{file}: {message}")]
    Toml { file: String, message: String },
    /// `what` (the start, an accepting state or a state's transition) names no state.
    #[error("{file}: {what} names no state `{name}`")]
    NoSuchState { file: String, what: String, name: String },
    #[error("{file}: state `{name}` is defined twice")]
    Twice { file: String, name: String },
    #[error("{file}: no accepting state")]
    NoAccepting { file: String },
    #[error("{fsa}: state `{state}` has no {trigger:?} transition")]
    NoTransition { fsa: String, state: String, trigger: Trigger },
}

/// The kinds of perceptual input that drive a transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Trigger {
    Normal,
    Terminal,
    Recoverable,
    Fatal,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StateSpec {
    name: String,
    #[serde(default)]
    perception: Option<String>,
    normal: String,
    terminal: String,
    recoverable: String,
    fatal: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    name: String,
    start: String,
    accept: Vec<String>,
    #[serde(rename = "state")]
    states: Vec<StateSpec>,
}

/// One state: its name, its perceptual algorithm, and its row of `δ` (indices into the states;
/// `None` where the acceptor has no transition, e.g. no fatal errors).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct State {
    pub name: String,
    pub perception: Option<String>,
    next: [Option<usize>; 4],
}

/// A finite state acceptor and where it is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fsa {
    pub name: String,
    pub states: Vec<State>,
    start: usize,
    accept: Vec<usize>,
    current: usize,
    /// Every state entered, the start first.
    pub trace: Vec<usize>,
}

impl Fsa {
    /// Parses and checks an acceptor; errors name the file and what is wrong.
    pub fn parse(text: &str, file: &str) -> Result<Self, FsaError> {
        let spec: Spec = toml::from_str(text)
            .map_err(|e| FsaError::Toml { file: file.to_owned(), message: e.to_string() })?;
        let index = |name: &str, what: &str| {
            spec.states.iter().position(|s| s.name == name).ok_or_else(|| FsaError::NoSuchState {
                file: file.to_owned(),
                what: what.to_owned(),
                name: name.to_owned(),
            })
        };
        if let Some(s) =
            spec.states.iter().find(|s| spec.states.iter().filter(|o| o.name == s.name).count() > 1)
        {
            return Err(FsaError::Twice { file: file.to_owned(), name: s.name.clone() });
        }
        let mut states = Vec::new();
        for s in &spec.states {
            let at = |to: &str, kind: &str| index(to, &format!("state `{}` {kind}", s.name));
            let fatal = s.fatal.as_deref().map(|f| at(f, "fatal")).transpose()?;
            let next = [
                Some(at(&s.normal, "normal")?),
                Some(at(&s.terminal, "terminal")?),
                Some(at(&s.recoverable, "recoverable")?),
                fatal,
            ];
            states.push(State { name: s.name.clone(), perception: s.perception.clone(), next });
        }
        let start = index(&spec.start, "start")?;
        let accept = spec.accept.iter().map(|a| index(a, "accept")).collect::<Result<Vec<_>, _>>()?;
        if accept.is_empty() {
            return Err(FsaError::NoAccepting { file: file.to_owned() });
        }
        Ok(Self { name: spec.name, states, start, accept, current: start, trace: vec![start] })
    }

    /// The state it is in.
    pub fn state(&self) -> &State {
        &self.states[self.current]
    }

    /// Whether it has reached an accepting state (the task is over, well or badly).
    pub fn accepted(&self) -> bool {
        self.accept.contains(&self.current)
    }

    /// Takes one trigger; returns the state entered. A trigger the state has no transition for
    /// is an error, and the acceptor stays where it was.
    pub fn step(&mut self, t: Trigger) -> Result<&State, FsaError> {
        let k = match t {
            Trigger::Normal => 0,
            Trigger::Terminal => 1,
            Trigger::Recoverable => 2,
            Trigger::Fatal => 3,
        };
        let to = self.states[self.current].next[k].ok_or_else(|| FsaError::NoTransition {
            fsa: self.name.clone(),
            state: self.state().name.clone(),
            trigger: t,
        })?;
        if to != self.current {
            self.trace.push(to);
        }
        self.current = to;
        Ok(&self.states[to])
    }

    /// Back to the start state (a fresh run of the task).
    pub fn reset(&mut self) {
        self.current = self.start;
        self.trace = vec![self.start];
    }

    /// The names of the states entered so far.
    pub fn trace_names(&self) -> Vec<&str> {
        self.trace.iter().map(|&i| self.states[i].name.as_str()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Trigger::*;

    fn load(name: &str) -> Fsa {
        let path = format!("{}/../../missions/fsa/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).expect("readable");
        Fsa::parse(&text, &path).expect("valid")
    }

    #[test]
    fn the_docking_acceptor_recovers_from_an_occluded_dock_as_in_the_paper() {
        let mut f = load("docking");
        assert_eq!(f.state().perception.as_deref(), Some("phototropic"));
        // Phototropic until close (terminal), the Hough finds the dock (normal), tracking...
        for t in [Normal, Normal, Terminal, Normal, Normal] {
            f.step(t).expect("a transition");
        }
        // ...an occluder breaks tracking (recoverable: back to the Hough), the Hough cannot see
        // the dock (recoverable: back to long range), then all goes well: 004 §4.2.2.
        for t in [Recoverable, Recoverable, Terminal, Normal, Normal, Terminal, Normal, Terminal] {
            f.step(t).expect("a transition");
        }
        assert_eq!(f.trace_names(), ["q0", "q1", "q2", "q1", "q0", "q1", "q2", "q3", "q4"]);
        assert!(f.accepted());
        assert_eq!(f.step(Fatal).expect("absorbing").name, "q4", "accepting states absorb");
        f.reset();
        assert_eq!(f.step(Fatal).expect("fatal").name, "q5");
        assert!(f.accepted());
    }

    #[test]
    fn the_move_to_pole_acceptor_has_no_fatal_errors_and_re_acquires_on_timeout() {
        let mut f = load("move-to-pole");
        for t in [
            Recoverable,
            Recoverable,
            Normal,
            Terminal,
            Normal,
            Normal,
            Recoverable,
            Terminal,
            Normal,
            Terminal,
            Terminal,
            Terminal,
        ] {
            f.step(t).expect("a transition");
        }
        assert_eq!(f.trace_names(), ["q0", "q1", "q2", "q0", "q1", "q2", "q3", "q4"]);
        assert!(f.accepted());
        f.reset();
        let e = f.step(Fatal).expect_err("no fatal transition").to_string();
        assert!(e.contains("state `q0` has no Fatal transition"), "{e}");
        assert_eq!(f.state().name, "q0");
    }

    #[test]
    fn bad_acceptors_are_rejected_with_the_reason() {
        let good = std::fs::read_to_string(format!(
            "{}/../../missions/fsa/docking.toml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .expect("readable");
        let e =
            Fsa::parse(&good.replace("terminal = \"q1\"", "terminal = \"q9\""), "d.toml").expect_err("bad");
        assert_eq!(e.to_string(), "d.toml: state `q0` terminal names no state `q9`");
        let e = Fsa::parse(&good.replace("start = \"q0\"", "start = \"qq\""), "d.toml").expect_err("bad");
        assert_eq!(e.to_string(), "d.toml: start names no state `qq`");
        let e = Fsa::parse(&good.replace("name = \"q5\"", "name = \"q4\""), "d.toml").expect_err("dup");
        assert_eq!(e.to_string(), "d.toml: state `q4` is defined twice");
        assert!(Fsa::parse("name = 3", "x.toml").expect_err("malformed").to_string().starts_with("x.toml:"));
    }
}
