//! The data files a launch names in `[launch] files` (acceptor tables and the like, relative to
//! the launch file): the recorder attaches them to the recording, and `harvey replay` puts them
//! back beside the replay's launch file, so that a recording replays on its own.

use std::path::{Component, Path};

/// Media type of a data file attached to a recording; the attachment's name is the file's path
/// relative to the launch file.
pub const DATA_MEDIA_TYPE: &str = "application/octet-stream; harvey-launch-data";

/// Whether `name` is a plain relative path that stays inside the launch file's folder: not empty,
/// no root, no `.` or `..` (a recording must not make a replay write elsewhere).
pub fn is_plain_relative(name: &str) -> bool {
    !name.is_empty() && Path::new(name).components().all(|c| matches!(c, Component::Normal(_)))
}

/// The `[launch] files` of launch file `file` (its text), checked to be plain relative paths.
pub fn named_in(text: &str, file: &str) -> Result<Vec<String>, String> {
    let doc: toml::Table = text.parse().map_err(|e| format!("{file}: {e}"))?;
    let Some(files) = doc.get("launch").and_then(|l| l.get("files")) else { return Ok(Vec::new()) };
    let files = files.as_array().ok_or(format!("{file}: `launch.files` is not a list"))?;
    files
        .iter()
        .map(|v| match v.as_str() {
            Some(name) if is_plain_relative(name) => Ok(name.to_owned()),
            _ => {
                Err(format!("{file}: `launch.files`: {v} is not a relative path inside the launch's folder"))
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_plain_relative_names_are_taken() {
        for ok in ["fsa/docking.toml", "table.toml"] {
            assert!(is_plain_relative(ok), "{ok}");
        }
        for bad in ["", "/etc/passwd", "../x.toml", "fsa/../../x", "./x.toml"] {
            assert!(!is_plain_relative(bad), "{bad}");
        }
        let text = "[launch]\nname = \"d\"\nfiles = [\"fsa/docking.toml\"]\n";
        assert_eq!(named_in(text, "d.toml"), Ok(vec!["fsa/docking.toml".to_owned()]));
        assert_eq!(named_in("[launch]\nname = \"d\"\n", "d.toml"), Ok(Vec::new()));
        let e = named_in("[launch]\nfiles = [\"../up.toml\"]\n", "d.toml").expect_err("escapes");
        assert!(e.contains("d.toml") && e.contains("../up.toml"), "{e}");
    }
}
