//! `harvey run [MISSION]`: launch a mission (the default one without an argument), record it and
//! print its summary; the exit code is the mission's.

use std::path::{Path, PathBuf};

use super::{LaunchArgs, launch_file};
use crate::summary::RunStats;

/// The mission `harvey run` runs without an argument.
pub const DEFAULT_MISSION: &str = "missions/default.toml";

pub fn run(mission: Option<&Path>, opts: &LaunchArgs) -> anyhow::Result<i32> {
    let file = mission.map_or_else(|| PathBuf::from(DEFAULT_MISSION), Path::to_path_buf);
    let (outcome, run_dir) = launch_file(&file, opts)?;
    let mcap = run_dir.join("run.mcap");
    println!("launch: {outcome:?}");
    if mcap.is_file() {
        let stats = RunStats::read(&mcap)?;
        print!("{}", stats.mission_summary());
        println!(
            "recording: {} ({} messages on {} topics)",
            mcap.display(),
            stats.message_count(),
            stats.topics.len()
        );
        let rrd = run_dir.join("run.rrd");
        if rrd.is_file() {
            println!("view it:   rerun {}", rrd.display());
        }
    }
    Ok(outcome.exit_code())
}
