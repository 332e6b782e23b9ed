//! Whether an output path is the input file itself, so that `harvey export`, `harvey recover` and
//! `harvey replay` refuse to write over the recording they read before they write anything: the
//! same canonical path (through symlinks, `..`, a relative path), or the same file under another
//! name (a hard link: the same device and inode).

use std::os::unix::fs::MetadataExt;
use std::path::Path;

use crate::RecordingError;

/// Whether `a` and `b` name one existing file. A path that does not exist is no file's.
pub fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(x), Ok(y)) = (std::fs::canonicalize(a), std::fs::canonicalize(b))
        && x == y
    {
        return true;
    }
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

/// An error when writing `output` would overwrite `input`.
pub fn refuse_overwrite(input: &Path, output: &Path) -> Result<(), RecordingError> {
    if same_file(input, output) {
        return Err(RecordingError::Overwrite { input: input.to_owned(), output: output.to_owned() });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_input_is_recognised_under_every_name() {
        let dir = std::env::temp_dir().join(format!("harvey-same-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).expect("tmp");
        let input = dir.join("in.mcap");
        std::fs::write(&input, b"x").expect("write");
        std::os::unix::fs::symlink(&input, dir.join("link.mcap")).expect("symlink");
        std::fs::hard_link(&input, dir.join("hard.mcap")).expect("hard link");
        for name in ["in.mcap", "link.mcap", "hard.mcap", "sub/../in.mcap", "./in.mcap"] {
            let e = refuse_overwrite(&input, &dir.join(name)).expect_err(name).to_string();
            assert!(e.ends_with("in.mcap itself: refusing to overwrite the recording read"), "{e}");
        }
        std::fs::write(dir.join("other.mcap"), b"x").expect("write");
        for name in ["other.mcap", "new.mcap", "sub/in.mcap"] {
            assert!(refuse_overwrite(&input, &dir.join(name)).is_ok(), "{name}");
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}
