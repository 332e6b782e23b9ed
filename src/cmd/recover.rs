//! `harvey recover RECORDING -o OUT`: salvage every complete chunk of a recording whose writer
//! died into a valid file.

use std::path::Path;

pub fn run(recording: &Path, output: &Path) -> anyhow::Result<i32> {
    let s = harvey_recording::recover::recover(recording, output)?;
    println!(
        "{}: {} messages and {} attachments salvaged{}",
        output.display(),
        s.messages,
        s.attachments,
        s.stopped_at.map(|e| format!(" (the rest was lost: {e})")).unwrap_or_default()
    );
    Ok(0)
}
