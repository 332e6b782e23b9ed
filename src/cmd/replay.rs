//! `harvey replay RECORDING [--check]`: run a recording's services again on its recorded inputs
//! and record them again; `--check` compares the new recording with the old.

use std::path::Path;

use super::replay_launch::prepare;
use super::{LaunchArgs, launch_file, report_comparison};

pub fn run(recording: &Path, check: bool, rrd: bool, opts: LaunchArgs) -> anyhow::Result<i32> {
    let run_dir =
        opts.run_dir.clone().unwrap_or_else(|| recording.parent().unwrap_or(Path::new(".")).join("replay"));
    let file = prepare(recording, &run_dir, rrd)?;
    let (outcome, _) = launch_file(&file, &LaunchArgs { run_dir: Some(run_dir.clone()), ..opts })?;
    println!("replay: {outcome:?}");
    let again = run_dir.join("run.mcap");
    println!("recording: {}", again.display());
    if outcome.exit_code() != 0 || !check {
        return Ok(outcome.exit_code());
    }
    let c = harvey_recording::compare::compare(recording, &again, &|_| true)?;
    Ok(report_comparison(&c, recording, &again))
}
