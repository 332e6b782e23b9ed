//! `harvey launch FILE`: the supervisor on a launch file, until its `end_with` service exits or
//! a signal stops it.

use std::path::Path;

use super::{LaunchArgs, launch_file};

pub fn run(file: &Path, opts: &LaunchArgs) -> anyhow::Result<i32> {
    let (outcome, _) = launch_file(file, opts)?;
    println!("launch: {outcome:?}");
    Ok(outcome.exit_code())
}
