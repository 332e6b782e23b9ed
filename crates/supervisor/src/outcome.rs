//! What a launch is given (its bus domain and run folder) and how it ended.

use std::path::PathBuf;

/// How a launch ended.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Outcome {
    /// The `end_with` service exited with this code (0: the mission is done).
    Ended { service: String, code: i32 },
    /// SIGINT or SIGTERM.
    Interrupted,
    /// A service failed more often than its policy allows.
    GaveUp { service: String },
    /// The launch ran past its wall-clock limit (`[launch] wall_limit_s`).
    WallLimit { limit_s: u64 },
}

impl Outcome {
    /// The process exit code the CLI returns.
    pub fn exit_code(&self) -> i32 {
        match self {
            Outcome::Ended { code, .. } => *code,
            Outcome::Interrupted => 130,
            Outcome::GaveUp { .. } => 1,
            // As timeout(1) exits.
            Outcome::WallLimit { .. } => 124,
        }
    }
}

/// Where and how to run a launch file.
#[derive(Debug, Clone)]
pub struct Options {
    pub prefix: String,
    pub run_dir: PathBuf,
}
