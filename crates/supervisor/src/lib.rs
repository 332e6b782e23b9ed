//! Harvey's supervisor: runs a launch file's services as processes, each started once the
//! previous is ready, restarted by a pure [`RestartPolicy`] (never / on-failure / always, with
//! doubling backoff and a limit within a window), and stopped in reverse order at the end.
//!
//! - [`config`] and [`LaunchFile`]: the launch-file format, checked with file, line and key.
//! - [`policy`]: the restart policy as pure state, fed with instants and exits.
//! - `child`: the thin spawn layer (process group, readiness pipe, PDEATHSIG, prefixed logs,
//!   stop with grace); `supervise`: the loop that ties them together.

pub mod bounds;
mod child;
mod clock;
pub mod config;
mod error;
mod launch_file;
mod outcome;
pub mod policy;
mod signals;
mod slots;
mod supervise;
mod supervisor;
mod wait;

pub use child::SpawnError;
pub use config::{LaunchError, LaunchFile};
pub use error::SupervisorError;
pub use outcome::{Options, Outcome};
pub use policy::{Decision, Restart, RestartPolicy, RestartRules};
pub use slots::find_binary;
pub use supervisor::run;
pub use wait::NotReady;
