//! `harvey diff A B`: compare two recordings message by message (topic, log time, payload);
//! exit 1 at the first difference, which it names.

use std::path::Path;

use super::report_comparison;

pub fn run(a: &Path, b: &Path) -> anyhow::Result<i32> {
    let c = harvey_recording::compare::compare(a, b, &|_| true)?;
    Ok(report_comparison(&c, a, b))
}
