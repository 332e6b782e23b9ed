//! `harvey run [MISSION]`: launch a mission (the default one without an argument), record it and
//! print its summary; the exit code is the mission's.

use std::path::{Path, PathBuf};

use super::{LaunchArgs, inproc, launch_file, launch_options};
use crate::summary::RunStats;

/// The mission `harvey run` runs without an argument.
pub const DEFAULT_MISSION: &str = "missions/default.toml";

pub fn run(mission: Option<&Path>, in_process: bool, opts: &LaunchArgs) -> anyhow::Result<i32> {
    let file = mission.map_or_else(|| PathBuf::from(DEFAULT_MISSION), Path::to_path_buf);
    let (outcome, run_dir) = match in_process {
        true => run_in_process(&file, opts)?,
        false => launch_file(&file, opts)?,
    };
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

/// Runs `file` in this process; how it ended and its run folder.
fn run_in_process(file: &Path, opts: &LaunchArgs) -> anyhow::Result<(harvey_supervisor::Outcome, PathBuf)> {
    let lf = harvey_supervisor::LaunchFile::load(file)?;
    let run_dir = launch_options(&lf, opts).run_dir;
    let ran = inproc::run(file, &run_dir)?;
    println!(
        "in process: {} ticks, {:.1} s simulated in {:.2} s ({:.0}x real time)",
        ran.ticks,
        ran.sim_s,
        ran.wall_s,
        ran.sim_s / ran.wall_s.max(1e-9)
    );
    println!("{}", inproc::turns_line(&ran.turns));
    Ok((ran.outcome, run_dir))
}
