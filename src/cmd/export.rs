//! `harvey export RECORDING -o OUT.rrd`: draw an MCAP recording into a Rerun file, with a progress
//! bar on a terminal.

use std::path::Path;

pub fn run(recording: &Path, output: &Path) -> anyhow::Result<i32> {
    // Refused before anything is read or written.
    harvey_recording::same_file::refuse_overwrite(recording, output)?;
    // A progress bar for people; logs get only the result line.
    let mut shown = if std::io::IsTerminal::is_terminal(&std::io::stderr()) { 0 } else { u64::MAX };
    let drawn = harvey_recording::export::export(recording, output, |done, total| {
        let pct = (done * 100).checked_div(total).unwrap_or(100);
        if pct >= shown {
            eprint!(
                "\rexporting {}: [{:<50}] {pct:>3}%",
                recording.display(),
                "#".repeat((pct / 2) as usize)
            );
            shown = pct + 2;
        }
    })?;
    if shown != u64::MAX {
        eprintln!();
    }
    println!("{}: {drawn} messages drawn", output.display());
    Ok(0)
}
