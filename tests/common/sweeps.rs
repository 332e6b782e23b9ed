//! A mission swept over seeds and conditions in process (`harvey sweep --in-process --keep`),
//! each run's folder handed to the caller while the scratch folder still holds it.

use std::path::Path;

/// Sweeps `mission` over `seeds` (`A..B`) under `conditions` and calls `read` with each run's
/// condition, seed, whether the mission logged its goal reached, and its folder (`run.mcap`,
/// `harvey-run.log`). Two runs at a time (a seed's two conditions, or two seeds of one), each
/// pair's recordings removed once read: a run keeps hundreds of MB, and CI's disk is finite.
pub fn sweep<T>(
    mission: &str,
    tag: &str,
    seeds: &str,
    conditions: &[&str],
    mut read: impl FnMut(&str, u64, bool, &Path) -> T,
) -> Vec<T> {
    let (lo, hi) = seeds.split_once("..").expect("a range");
    let (lo, hi): (u64, u64) = (lo.parse().expect("seed"), hi.parse().expect("seed"));
    let joined = conditions.join(",");
    // Two runs at once: one seed's two conditions, or two seeds of one.
    let per = (2 / conditions.len()).max(1) as u64;
    let mut rows = Vec::new();
    for first in (lo..=hi).step_by(per as usize) {
        let last = (first + per - 1).min(hi);
        let (prefix, out) = (super::unique_prefix(tag), super::scratch(tag));
        let range = format!("{first}..{last}");
        let args = ["sweep", mission, "--seeds", &range, "--conditions", &joined, "--in-process"];
        let run = super::harvey(&args)
            .args(["--jobs", "2", "--keep", "--out", out.to_str().expect("utf8"), "--prefix", &prefix])
            .output()
            .expect("runs");
        let said =
            || format!("{}{}", String::from_utf8_lossy(&run.stdout), String::from_utf8_lossy(&run.stderr));
        for seed in first..=last {
            for c in conditions {
                let dir = out.join("runs").join(format!("{c}-s{seed}"));
                assert!(
                    dir.join("run.mcap").is_file(),
                    "{c} s{seed} left no recording; the sweep said:\n{}",
                    said()
                );
                let log = std::fs::read_to_string(dir.join("harvey-run.log")).unwrap_or_default();
                rows.push(read(c, seed, log.contains("goal reached"), &dir));
            }
        }
    }
    rows
}
