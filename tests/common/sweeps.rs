//! A mission swept over seeds and conditions in process (`harvey sweep --in-process --keep`),
//! each run's folder handed to the caller while the scratch folder still holds it.

use std::path::Path;

/// Sweeps `mission` over `seeds` (`A..B`) under `conditions`, two runs at a time, and calls
/// `read` with each run's condition, seed, whether the mission logged its goal reached, and its
/// folder (`run.mcap`, `harvey-run.log`).
pub fn sweep<T>(
    mission: &str,
    tag: &str,
    seeds: &str,
    conditions: &[&str],
    mut read: impl FnMut(&str, u64, bool, &Path) -> T,
) -> Vec<T> {
    let (prefix, out) = (super::unique_prefix(tag), super::scratch(tag));
    let joined = conditions.join(",");
    let args = ["sweep", mission, "--seeds", seeds, "--conditions", &joined, "--in-process"];
    let run = super::harvey(&args)
        .args(["--jobs", "2", "--keep", "--out", out.to_str().expect("utf8"), "--prefix", &prefix])
        .output()
        .expect("runs");
    assert!(out.join("sweep.csv").exists(), "{}", String::from_utf8_lossy(&run.stderr));
    let (lo, hi) = seeds.split_once("..").expect("a range");
    let (lo, hi): (u64, u64) = (lo.parse().expect("seed"), hi.parse().expect("seed"));
    let mut rows = Vec::new();
    for c in conditions {
        for seed in lo..=hi {
            let dir = out.join("runs").join(format!("{c}-s{seed}"));
            let log = std::fs::read_to_string(dir.join("harvey-run.log")).unwrap_or_default();
            rows.push(read(c, seed, log.contains("goal reached"), &dir));
        }
    }
    rows
}
