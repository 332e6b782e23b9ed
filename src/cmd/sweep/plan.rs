//! What a sweep will run: the seed range of `--seeds A..B`, and per run a copy of the mission's
//! launch file with its seed and merged world, written next to the original (under a hidden
//! name) so that the files it names relative to itself still resolve.

use std::path::{Path, PathBuf};

/// A `--seeds` argument that names no seeds.
#[derive(Debug, thiserror::Error)]
pub enum SeedError {
    #[error("argument `--seeds {given}`: {detail}")]
    Bad { given: String, detail: String },
}

/// The largest seed a launch file can hold (a TOML integer is an i64).
const MAX_SEED: u64 = i64::MAX as u64;

/// `A..B` (both included; `A..=B` too) or one seed `A`.
pub fn parse_seeds(given: &str) -> Result<Vec<u64>, SeedError> {
    let bad = |detail: String| SeedError::Bad { given: given.to_owned(), detail };
    let num = |s: &str| -> Result<u64, SeedError> {
        let n: u64 =
            s.trim().parse().map_err(|_| bad(format!("`{}` is not a seed (0 to {MAX_SEED})", s.trim())))?;
        if n > MAX_SEED {
            return Err(bad(format!("seed {n} is larger than {MAX_SEED}")));
        }
        Ok(n)
    };
    let (a, b) = match given.split_once("..") {
        Some((a, b)) => (num(a)?, num(b.strip_prefix('=').unwrap_or(b))?),
        None => {
            let a = num(given)?;
            (a, a)
        }
    };
    if b < a {
        return Err(bad(format!("the range is empty ({b} < {a}); give A..B with A <= B, both included")));
    }
    if b - a >= 100_000 {
        return Err(bad(format!("{} seeds; a sweep runs at most 100000", b - a + 1)));
    }
    Ok((a..=b).collect())
}

/// The hidden copy of `mission` for one run, in the mission's folder.
pub fn launch_copy_path(mission: &Path, tag: &str) -> PathBuf {
    let stem = mission.file_stem().map_or_else(|| "mission".into(), |s| s.to_string_lossy().into_owned());
    mission.with_file_name(format!(".sweep-{}-{stem}-{tag}.toml", std::process::id()))
}

/// The hidden merged world of one condition, in the mission's folder.
pub fn world_copy_path(mission: &Path, condition: &str) -> PathBuf {
    mission.with_file_name(format!(".sweep-{}-world-{condition}.toml", std::process::id()))
}

/// The launch file `text` with `[launch] seed = seed` and `world = world` (a path relative to
/// the launch file's folder, or absolute); without `rrd`, the recorder draws no Rerun file (its
/// `--rrd PATH` dropped: a sweep is for figures, and each run's drawing is as large as its
/// recording; `harvey export` draws a kept recording afterwards).
pub fn launch_copy(text: &str, seed: u64, world: &Path, rrd: bool) -> Result<String, anyhow::Error> {
    let mut launch: toml::Table = toml::from_str(text)?;
    if !rrd && let Some(services) = launch.get_mut("service").and_then(toml::Value::as_array_mut) {
        crate::cmd::rrd_arg::drop_rrd(services);
    }
    let settings = launch
        .get_mut("launch")
        .and_then(toml::Value::as_table_mut)
        .ok_or_else(|| anyhow::anyhow!("the launch file has no [launch] table"))?;
    let seed = i64::try_from(seed)?;
    settings.insert("seed".into(), toml::Value::Integer(seed));
    settings.insert("world".into(), toml::Value::String(world.display().to_string()));
    Ok(toml::to_string(&launch)?)
}

/// Files a sweep wrote for its runs, removed when it ends however it ends.
#[derive(Default)]
pub struct TempFiles(pub Vec<PathBuf>);

impl Drop for TempFiles {
    fn drop(&mut self) {
        for f in &self.0 {
            let _ = std::fs::remove_file(f);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_ranges_include_both_ends() {
        assert_eq!(parse_seeds("1..4").expect("ok"), [1, 2, 3, 4]);
        assert_eq!(parse_seeds("3..=5").expect("ok"), [3, 4, 5]);
        assert_eq!(parse_seeds("7").expect("ok"), [7]);
        assert_eq!(parse_seeds("2..2").expect("ok"), [2]);
    }

    #[test]
    fn empty_or_bad_ranges_are_refused_naming_the_argument() {
        let e = parse_seeds("3..2").expect_err("empty").to_string();
        assert!(e.starts_with("argument `--seeds 3..2`: the range is empty"), "{e}");
        assert!(parse_seeds("a..2").expect_err("bad").to_string().contains("`a` is not a seed"));
        assert!(parse_seeds("-1..2").is_err());
        assert!(parse_seeds("1..99999999999999999999").is_err());
        assert!(parse_seeds("0..100000").expect_err("too many").to_string().contains("at most"));
    }

    #[test]
    fn the_copy_sets_seed_and_world_and_keeps_the_rest() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/missions/docking.toml"))
            .expect("mission");
        let copy = launch_copy(&text, 8, Path::new("/tmp/w.toml"), true).expect("copy");
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/missions/.x.toml"));
        let lf = harvey_supervisor::LaunchFile::parse(&copy, path).expect("still a launch file");
        let orig = harvey_supervisor::LaunchFile::parse(&text, path).expect("launch file");
        assert_eq!(lf.settings.seed, 8);
        assert_eq!(lf.world_path(), Some(PathBuf::from("/tmp/w.toml")));
        assert_eq!(lf.services.len(), orig.services.len());
        let [a, b]: [toml::Table; 2] = [&copy, &text].map(|t| toml::from_str(t).expect("toml"));
        assert_eq!(a.get("mission"), b.get("mission"));
        assert_eq!(a.get("service"), b.get("service"), "with `rrd`, the services as they were");
    }

    #[test]
    fn without_rrd_the_recorder_draws_no_rerun_file_and_keeps_its_other_arguments() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/missions/docking.toml"))
            .expect("mission");
        let recorder = |t: &str| {
            let lf = harvey_supervisor::LaunchFile::parse(t, Path::new("/m/x.toml")).expect("launch file");
            lf.services.into_iter().find(|s| s.name.get_ref() == "recorder").expect("a recorder").args
        };
        let before = recorder(&text);
        let at = before.iter().position(|a| a == "--rrd").expect("the mission draws a Rerun file");
        let after = recorder(&launch_copy(&text, 1, Path::new("w.toml"), false).expect("copy"));
        let mut expected = before.clone();
        expected.drain(at..at + 2);
        assert_eq!(after, expected);
        assert!(after.iter().any(|a| a == "--output"), "{after:?}");
    }
}
