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

/// A launch file's `[launch] files` that cannot be taken.
#[derive(Debug, thiserror::Error)]
pub enum DataFilesError {
    /// The launch file is not TOML.
    #[error("{file}: {cause}")]
    Toml { file: String, cause: toml::de::Error },
    #[error("{file}: `launch.files` is not a list")]
    NotAList { file: String },
    /// An entry that is not a string, or a path that leaves the launch file's folder.
    #[error("{file}: `launch.files`: {value} is not a relative path inside the launch's folder")]
    Escapes { file: String, value: toml::Value },
}

/// The `[launch] files` of launch file `file` (its text), checked to be plain relative paths.
pub fn named_in(text: &str, file: &str) -> Result<Vec<String>, DataFilesError> {
    let doc: toml::Table =
        text.parse().map_err(|cause| DataFilesError::Toml { file: file.to_owned(), cause })?;
    let Some(files) = doc.get("launch").and_then(|l| l.get("files")) else { return Ok(Vec::new()) };
    let files = files.as_array().ok_or_else(|| DataFilesError::NotAList { file: file.to_owned() })?;
    files
        .iter()
        .map(|v| match v.as_str() {
            Some(name) if is_plain_relative(name) => Ok(name.to_owned()),
            _ => Err(DataFilesError::Escapes { file: file.to_owned(), value: v.clone() }),
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
        assert_eq!(named_in(text, "d.toml").expect("names"), ["fsa/docking.toml"]);
        assert_eq!(named_in("[launch]\nname = \"d\"\n", "d.toml").expect("none"), Vec::<String>::new());
        let e = named_in("[launch]\nfiles = [\"../up.toml\"]\n", "d.toml").expect_err("escapes").to_string();
        assert!(e.contains("d.toml") && e.contains("../up.toml"), "{e}");
    }
}
