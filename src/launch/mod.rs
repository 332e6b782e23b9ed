//! `harvey launch`: launch files and the supervisor that runs them.

mod child;
mod clock;
pub mod config;
pub mod supervisor;

pub use config::LaunchFile;
pub use supervisor::{Options, Outcome, run};
