//! Harvey's supervisor: runs a launch file's services as processes, each started once the
//! previous is ready, restarted by a pure [`RestartPolicy`] (never / on-failure / always, with
//! doubling backoff and a limit within a window), and stopped in reverse order at the end.
//!
//! - [`config`] and [`LaunchFile`]: the launch-file format, checked with file, line and key.
//! - [`policy`]: the restart policy as pure state, fed with instants and exits.
//! - [`keep`]: the keeper, the launch's outer process: it starts every process (`spawn`), reaps
//!   them, and starts a new supervisor when one dies (`link`: the line between the two).
//! - `child` and `keeper_line`: the supervisor's side of a service process (spawned by the
//!   keeper, waited for until ready, stopped with grace); `supervise`: the loop that ties
//!   policy, clock and children together.

pub mod bounds;
mod child;
mod clock;
pub mod config;
mod error;
mod keeper;
mod keeper_line;
mod launch_file;
mod link;
mod outcome;
pub mod policy;
mod signals;
mod slots;
mod spawn;
mod supervise;
mod supervisor;
mod wait;

pub use child::SpawnError;
pub use config::{ClockMode, LaunchError, LaunchFile};
pub use error::SupervisorError;
pub use keeper::{Kept, keep};
pub use keeper_line::KeeperLine;
pub use outcome::{Options, Outcome};
pub use policy::{Decision, Restart, RestartPolicy, RestartRules};
pub use slots::{expand_args, find_binary, variables};
pub use supervisor::run;
pub use wait::NotReady;
