//! The mutation harness at bench scale: 10,000 seeded mutations (cuts, bit flips, length fields
//! rewritten, CRCs edited) of a small recording through each tool entry point of the crate
//! (`HARVEY_MUTATIONS` sets another count), printing per tool and kind of damage how many cases
//! were run, reported as damaged, read exactly as the intact file, read otherwise (lies) and
//! panicked, and the slowest case. Fails when any case panicked or lied.
//! `cargo bench -p harvey-recording --bench mutations`.
//!
//! The cases run in child processes of 1,000 (this binary again, `--slice TOOL SEED CASES`), two
//! at a time: rerun 0.36 leaks the two threads of the in-memory stream that builds a blueprint
//! with every `RrdWriter`, harmless in a process that exports once, fatal after ten thousand.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "bench code")]

#[path = "../tests/mutation/mod.rs"]
mod mutation;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use mutation::Campaign;
use mutation::mutate::KINDS;
use mutation::tools::TOOLS;

const SLICE: usize = 1_000;

/// Runs one slice and prints it, a line per kind of damage and per failure.
fn slice(tool: &str, seed: u64, cases: usize) {
    let &(name, entry) = TOOLS.iter().find(|(name, _)| *name == tool).expect("a tool");
    let c = mutation::campaign(name, entry, cases, seed);
    for (kind, t) in &c.by_kind {
        let slowest = t.slowest.as_nanos();
        println!(
            "T {kind:?} {} {} {} {} {} {slowest}",
            t.cases, t.reported, t.identical, t.different, t.panics
        );
    }
    for f in &c.failures {
        println!("F {f}");
    }
}

/// Adds the slice a child printed to `c`.
fn merge(c: &mut Campaign, printed: &str) {
    for line in printed.lines() {
        if let Some(f) = line.strip_prefix("F ") {
            c.failures.push(f.to_owned());
        }
        let Some(t) = line.strip_prefix("T ") else { continue };
        let f: Vec<&str> = t.split(' ').collect();
        let kind = *KINDS.iter().find(|k| format!("{k:?}") == f[0]).expect("a kind");
        let n: Vec<u64> = f[1..].iter().map(|n| n.parse().expect("a count")).collect();
        let t = c.by_kind.entry(kind).or_default();
        t.cases += n[0];
        t.reported += n[1];
        t.identical += n[2];
        t.different += n[3];
        t.panics += n[4];
        t.slowest = t.slowest.max(Duration::from_nanos(n[5]));
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--slice") {
        slice(&args[i + 1], args[i + 2].parse().expect("seed"), args[i + 3].parse().expect("cases"));
        return;
    }
    let cases = std::env::var("HARVEY_MUTATIONS").ok().and_then(|n| n.parse().ok()).unwrap_or(10_000);
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).map(|l| l.to_owned()))
        .unwrap_or_default();
    println!("{cases} mutations per tool; {cpu}");
    let start = Instant::now();
    let exe = std::env::current_exe().expect("this bench");
    let mut jobs = Vec::new();
    for (t, (name, _)) in TOOLS.iter().enumerate() {
        for (s, first) in (0..cases).step_by(SLICE).enumerate() {
            jobs.push((t, *name, 1_000 * (t as u64 + 1) + s as u64, SLICE.min(cases - first)));
        }
    }
    let mut campaigns: Vec<Campaign> = TOOLS.iter().map(|_| Campaign::default()).collect();
    for pair in jobs.chunks(2) {
        let children: Vec<_> = pair
            .iter()
            .map(|&(t, name, seed, n)| {
                let mut child = Command::new(&exe);
                child.args(["--slice", name, &seed.to_string(), &n.to_string()]);
                (t, child.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("a slice starts"))
            })
            .collect();
        for (t, child) in children {
            let out = child.wait_with_output().expect("a slice runs");
            assert!(out.status.success(), "{}: {}", TOOLS[t].0, String::from_utf8_lossy(&out.stderr));
            merge(&mut campaigns[t], &String::from_utf8_lossy(&out.stdout));
        }
    }
    let rows: Vec<(&str, &Campaign)> = TOOLS.iter().map(|(n, _)| *n).zip(&campaigns).collect();
    print!("{}", mutation::table(&rows));
    println!("{:.1} s", start.elapsed().as_secs_f64());
    for (name, c) in &rows {
        mutation::assert_kept(name, c);
    }
}
