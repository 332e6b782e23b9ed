//! The CLI's commands, one file each, and what several of them share: launching a launch file
//! under the supervisor and reporting a comparison of two recordings.

pub mod chaos;
pub mod diff;
pub mod export;
pub mod info;
pub mod launch;
pub mod recover;
pub mod replay;
mod replay_launch;
pub mod run;
pub mod sweep;

use std::path::{Path, PathBuf};

/// Where a launch writes and which bus domain it uses.
#[derive(clap::Args)]
pub struct LaunchArgs {
    /// Output folder (default: recordings/<launch name>).
    #[arg(long)]
    pub run_dir: Option<PathBuf>,
    /// Bus domain prefix; runs with different prefixes never see each other.
    #[arg(long, default_value = harvey_bus::DEFAULT_PREFIX)]
    pub prefix: String,
}

/// Runs launch file `file` under the supervisor; returns how it ended and its run folder.
fn launch_file(file: &Path, args: &LaunchArgs) -> anyhow::Result<(harvey_supervisor::Outcome, PathBuf)> {
    let lf = harvey_supervisor::LaunchFile::load(file)?;
    let run_dir = args.run_dir.clone().unwrap_or_else(|| Path::new("recordings").join(&lf.settings.name));
    let opts = harvey_supervisor::Options { prefix: args.prefix.clone(), run_dir: run_dir.clone() };
    tracing::info!(launch = %lf.settings.name, run_dir = %run_dir.display(), prefix = %opts.prefix, "launching {} services", lf.services.len());
    Ok((harvey_supervisor::run(&lf, &opts)?, run_dir))
}

/// Prints the outcome of a comparison; the exit code is 0 when the recordings agree.
fn report_comparison(c: &harvey_recording::compare::Comparison, a: &Path, b: &Path) -> i32 {
    match &c.first_difference {
        None => {
            println!("identical: {} messages of {} and {} agree", c.messages, a.display(), b.display());
            0
        }
        Some(d) => {
            println!("DIFFERENT at message {}: {}", d.index, d.detail);
            1
        }
    }
}
