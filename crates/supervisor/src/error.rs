//! Why a launch could not run: set-up errors found before anything starts, and failures of the
//! bus or of a child on the way.

use std::path::PathBuf;

use harvey_bus::{BusError, NodeInfo};

use crate::child::SpawnError;

/// A launch that could not run (a service giving up is an [`crate::Outcome`], not an error).
#[derive(Debug, thiserror::Error)]
pub enum SupervisorError {
    #[error(transparent)]
    Bus(#[from] BusError),
    #[error("creating {}", path.display())]
    RunDir {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: key `launch.world`: {} does not exist", launch.display(), world.display())]
    NoWorld { launch: PathBuf, world: PathBuf },
    #[error(
        "{}: service `{service}`: executable `{binary}` not found beside harvey or on PATH (build it with `cargo build --release --workspace`)",
        launch.display()
    )]
    NoBinary { launch: PathBuf, service: String, binary: String },
    #[error("bus prefix `{prefix}` already runs {clashes:?}: is another launch running?")]
    Clash { prefix: String, clashes: Vec<NodeInfo> },
    #[error("installing signal handlers")]
    Signals(#[source] std::io::Error),
    #[error(transparent)]
    Spawn(#[from] SpawnError),
    #[error("the supervisor's keeper: {0}")]
    Keeper(String),
}

/// `e` and its sources, joined by `: ` (what `{:#}` shows for an `anyhow` error).
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}
