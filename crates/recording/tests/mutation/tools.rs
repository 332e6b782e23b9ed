//! The tool entry points the mutation harness runs on each damaged file, each reduced to an
//! [`Output`]: a fingerprint per part of what the tool yields, `None` for a part the tool
//! reported as damaged. An `Err` is a broken promise found on the way (`recover` writing a message
//! the input never had, or a file that does not read back).

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::Path;

use harvey_recording::{Recording, RecordingError, compare, export, recover, ticks};

/// A fingerprint per part of a tool's output; `None` where it reported damage.
pub type Output = Vec<Option<u64>>;

/// What a tool runs on: the intact original, the damaged copy, a folder for what it writes, and
/// the original's messages (fingerprints, in order).
pub struct Case<'a> {
    pub original: &'a Path,
    pub mutated: &'a Path,
    pub scratch: &'a Path,
    pub messages: &'a [u64],
}

/// A tool: its name and its entry point.
pub type Tool = (&'static str, fn(&Case<'_>) -> Result<Output, String>);

/// Every tool of the crate.
pub const TOOLS: [Tool; 6] = [
    ("messages", messages),
    ("compare", compare_tool),
    ("recover", recover_tool),
    ("export", export_tool),
    ("ticks", ticks_tool),
    ("attachments", attachments),
];

pub fn fingerprint(value: &impl Hash) -> u64 {
    let mut h = DefaultHasher::new();
    value.hash(&mut h);
    h.finish()
}

/// The fingerprints of `path`'s messages, in order.
pub fn message_prints(path: &Path) -> Result<Vec<u64>, RecordingError> {
    let r = Recording::open(path)?;
    let mut prints = Vec::new();
    for m in r.messages()? {
        let m = m?;
        prints.push(fingerprint(&(m.topic(), m.schema(), m.sequence(), m.log_time(), m.data())));
    }
    Ok(prints)
}

/// `Recording::open` and `messages()`.
pub fn messages(case: &Case<'_>) -> Result<Output, String> {
    Ok(vec![message_prints(case.mutated).ok().map(|p| fingerprint(&p))])
}

/// `harvey diff`: the original against the damaged copy; a difference is damage reported.
fn compare_tool(case: &Case<'_>) -> Result<Output, String> {
    Ok(vec![match compare::compare(case.original, case.mutated, &|_| true) {
        Ok(c) if c.first_difference.is_none() => Some(c.messages as u64),
        _ => None,
    }])
}

/// `harvey recover` into a temporary file. Whatever it salvages must read back, and every
/// message of it must be one of the original's, in order: a damaged chunk is never written again
/// as good. Anything skipped or lost is damage reported.
fn recover_tool(case: &Case<'_>) -> Result<Output, String> {
    let out = case.scratch.join("recovered.mcap");
    let Ok(salvage) = recover::recover(case.mutated, &out) else { return Ok(vec![None]) };
    let prints = message_prints(&out).map_err(|e| format!("the salvage does not read back: {e}"))?;
    let mut original = case.messages.iter();
    if let Some(i) = prints.iter().position(|p| !original.any(|o| o == p)) {
        return Err(format!("salvaged message {i} is not the original's ({salvage:?})"));
    }
    if salvage.messages != prints.len() as u64 {
        return Err(format!("{salvage:?}, but {} messages read back", prints.len()));
    }
    let r = Recording::open(&out).map_err(|e| e.to_string())?;
    let carried = (r.launch_text().ok(), r.world_text().ok(), r.seq_gaps().ok(), data_files(&r));
    Ok(vec![salvage.is_whole().then(|| fingerprint(&(prints, carried)))])
}

fn data_files(r: &Recording) -> Option<Vec<(String, Vec<u8>)>> {
    let files = r.data_files().ok()?;
    files.map(|f| f.ok().map(|f| (f.name, f.data.into_owned()))).collect()
}

/// `harvey export` into a temporary Rerun file: the messages drawn, and whether the world was
/// there to draw (a world that does not load is warned about and left out).
fn export_tool(case: &Case<'_>) -> Result<Output, String> {
    let drawn = export::export(case.mutated, &case.scratch.join("out.rrd"), |_, _| {}).ok();
    let world =
        Recording::open(case.mutated).ok().and_then(|r| r.world().ok()).map(|w| fingerprint(&w.is_some()));
    Ok(vec![drawn, world])
}

/// The replayer's input: the recording split into ticks.
fn ticks_tool(case: &Case<'_>) -> Result<Output, String> {
    let Ok(r) = Recording::open(case.mutated) else { return Ok(vec![None]) };
    let mut h = DefaultHasher::new();
    let c = ticks::for_each_tick::<RecordingError>(&r, |stamp, inputs| {
        (stamp, format!("{inputs:?}")).hash(&mut h);
        Ok(())
    });
    Ok(vec![c.ok().map(|c| fingerprint(&(format!("{c:?}"), h.finish())))])
}

/// What the recording carries: launch, world text, data files, the world placed by its seed, the
/// recorder's counts.
fn attachments(case: &Case<'_>) -> Result<Output, String> {
    let Ok(r) = Recording::open(case.mutated) else { return Ok(vec![None; 5]) };
    let world = r.world().ok().map(|w| {
        w.map(|(w, poles)| {
            format!("{:?} {poles:?}", w.walls.iter().map(|w| (w.from, w.to)).collect::<Vec<_>>())
        })
    });
    Ok(vec![
        r.launch_text().ok().map(|t| fingerprint(&t)),
        r.world_text().ok().map(|t| fingerprint(&t)),
        data_files(&r).map(|f| fingerprint(&f)),
        world.map(|w| fingerprint(&w)),
        r.seq_gaps().ok().map(|g| fingerprint(&g)),
    ])
}
