//! `harvey info RECORDING`: topics, counts, rates, duration and sequence gaps of a recording, and
//! its mission summary when it has one.

use std::path::Path;

use crate::summary::RunStats;

pub fn run(recording: &Path) -> anyhow::Result<i32> {
    let stats = RunStats::read(recording)?;
    print!("{}", stats.info_table());
    if stats.last_status.is_some() {
        print!("{}", stats.mission_summary());
    }
    Ok(0)
}
