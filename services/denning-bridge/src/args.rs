//! The bridge's arguments, as a launch line gives them.

use std::path::PathBuf;

use clap::Parser;

#[derive(Parser)]
#[command(about = "Bridge between a Denning DRV serial line and the Harvey bus")]
pub struct Args {
    /// Serial device of the DRV (or the simulated DRV's pseudo-terminal link).
    #[arg(long)]
    pub device: PathBuf,
    /// After a panic-stop, refuse motion commands for this long (simulated or sensor time).
    #[arg(long, default_value_t = 200)]
    pub panic_hold_ms: u64,
    /// Stop the vehicle when neither a status nor a command has come from the executive for
    /// this long (vehicle time, from the DRV's reports), and on shutdown.
    #[arg(long, default_value_t = 200)]
    pub watchdog_ms: u64,
    /// When the line hangs up (or is not there yet), keep trying to open it for this long
    /// before giving up.
    #[arg(long, default_value_t = 10.0)]
    pub reopen_s: f64,
}
