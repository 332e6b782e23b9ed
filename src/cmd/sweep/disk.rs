//! The disk a sweep writes to: a failed run keeps its recording (a 20-minute `poles` run under
//! noise keeps some 6 GB), so a sweep starts a run only while the disk has room for two more of
//! the largest it has kept, and ends cleanly, naming the folder, when it has not.

use std::path::Path;

/// Room kept free before the first run has been measured.
const FLOOR_BYTES: u64 = 1 << 30;

/// The bytes free to an unprivileged writer on the file system holding `dir`.
pub fn free_bytes(dir: &Path) -> anyhow::Result<u64> {
    let s = nix::sys::statvfs::statvfs(dir)
        .map_err(|e| anyhow::anyhow!("cannot read the free space of {}: {e}", dir.display()))?;
    Ok(s.blocks_available().saturating_mul(s.fragment_size()))
}

/// The bytes of the files under `dir` (0 where it is gone).
pub fn size_of(dir: &Path) -> u64 {
    let Ok(entries) = std::fs::read_dir(dir) else { return 0 };
    entries
        .flatten()
        .map(|e| match e.file_type() {
            Ok(t) if t.is_dir() => size_of(&e.path()),
            Ok(_) => e.metadata().map_or(0, |m| m.len()),
            Err(_) => 0,
        })
        .sum()
}

/// The room a next run needs: twice the largest run folder kept so far, at least the floor.
#[derive(Debug, Default)]
pub struct Reserve {
    largest: u64,
}

impl Reserve {
    /// A finished run's folder, as it is kept.
    pub fn kept(&mut self, run_dir: &Path) {
        self.largest = self.largest.max(size_of(run_dir));
    }

    pub fn needed(&self) -> u64 {
        self.largest.saturating_mul(2).max(FLOOR_BYTES)
    }

    /// `None` when `free` bytes are room enough for another run; else why not, naming `dir`.
    pub fn short(&self, dir: &Path, free: u64) -> Option<String> {
        let gib = |b: u64| b as f64 / f64::from(1u32 << 30);
        (free < self.needed()).then(|| {
            format!(
                "{} has {:.1} GiB free, under the {:.1} GiB another run may keep (twice the largest run folder kept so far)",
                dir.display(),
                gib(free),
                gib(self.needed())
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_starts_only_with_room_for_two_of_the_largest_kept() {
        let dir = std::env::temp_dir().join(format!("harvey-disk-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("run/inner")).expect("dir");
        std::fs::write(dir.join("run/a"), vec![0u8; 3000]).expect("write");
        std::fs::write(dir.join("run/inner/b"), vec![0u8; 2000]).expect("write");
        assert_eq!(size_of(&dir.join("run")), 5000);
        assert_eq!(size_of(&dir.join("gone")), 0);
        let mut r = Reserve::default();
        assert_eq!(r.needed(), FLOOR_BYTES, "the floor before any run");
        r.kept(&dir.join("run"));
        assert_eq!(r.needed(), FLOOR_BYTES, "small runs: still the floor");
        r.largest = 6 << 30;
        assert!(r.short(&dir, 13 << 30).is_none());
        let why = r.short(&dir, 11 << 30).expect("short");
        assert!(why.contains(&dir.display().to_string()) && why.contains("11.0 GiB free"), "{why}");
        assert!(free_bytes(&dir).expect("statvfs") > 0);
        std::fs::remove_dir_all(&dir).expect("clean");
    }
}
