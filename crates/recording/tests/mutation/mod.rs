//! The mutation harness: a small valid recording (`sample.rs`) damaged by seeded mutations
//! (`mutate.rs`) and read by each tool entry point (`tools.rs`), each case inside
//! `catch_unwind` to count panics. Every case must end with the damage reported, or with exactly
//! what the tool yields for the intact file; never a panic, never another answer.
//! `tests/mutations.rs` runs it in CI, `benches/mutations.rs` at ten times the cases.

pub mod mutate;
pub mod sample;
pub mod tools;

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use harvey_geometry::Rng;

use mutate::{KINDS, Kind};
use tools::{Case, Output};

/// What became of the cases of one kind of damage.
#[derive(Debug, Default, Clone, Copy)]
pub struct Tally {
    pub cases: u64,
    /// Damage reported (an error, or a part of the output marked damaged).
    pub reported: u64,
    /// Exactly the intact file's output (damage the tool does not read, or does not notice).
    pub identical: u64,
    /// Another output than the intact file's, with no damage reported: a lie.
    pub different: u64,
    pub panics: u64,
    /// The slowest case.
    pub slowest: Duration,
}

/// A campaign's tallies by kind of damage, and the first failures (kind, mutation, what).
#[derive(Debug, Default)]
pub struct Campaign {
    pub by_kind: BTreeMap<Kind, Tally>,
    pub failures: Vec<String>,
}

impl Campaign {
    pub fn total(&self) -> Tally {
        self.by_kind.values().fold(Tally::default(), |a, t| Tally {
            cases: a.cases + t.cases,
            reported: a.reported + t.reported,
            identical: a.identical + t.identical,
            different: a.different + t.different,
            panics: a.panics + t.panics,
            slowest: a.slowest.max(t.slowest),
        })
    }
}

/// A fresh folder for one campaign's files.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("harvey-mutations-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// Whether `got` is the intact output, damage reported, or neither.
fn verdict(intact: &Output, got: &Output) -> Result<bool, String> {
    if got.len() != intact.len() || got.iter().zip(intact).any(|(g, i)| g.is_some() && g != i) {
        return Err(format!("{got:?} instead of {intact:?}"));
    }
    Ok(got.iter().any(Option::is_none))
}

/// Runs `cases` mutations (the kinds in turn) of the sample through `tool`, seeded by `seed`.
pub fn campaign(
    name: &str,
    tool: fn(&Case<'_>) -> Result<Output, String>,
    cases: usize,
    seed: u64,
) -> Campaign {
    let dir = scratch(name);
    let (original, mutated) = (dir.join("original.mcap"), dir.join("mutated.mcap"));
    sample::write(&original);
    let bytes = std::fs::read(&original).expect("sample");
    let layout = mutate::layout(&bytes);
    let messages = tools::message_prints(&original).expect("the sample reads");
    let case = Case { original: &original, mutated: &original, scratch: &dir, messages: &messages };
    let intact = tool(&case).expect("the tool runs on the intact file");
    assert!(intact.iter().all(Option::is_some), "{name} reports damage in the intact file: {intact:?}");
    let mut rng = Rng::new(seed);
    let mut out = Campaign::default();
    for i in 0..cases {
        let kind = KINDS[i % KINDS.len()];
        let (damaged, what) = mutate::mutate(&bytes, &layout, kind, &mut rng);
        std::fs::write(&mutated, &damaged).expect("write the damaged copy");
        let case = Case { mutated: &mutated, ..case };
        let start = Instant::now();
        let result = catch_unwind(AssertUnwindSafe(|| tool(&case)));
        let t = out.by_kind.entry(kind).or_default();
        t.cases += 1;
        t.slowest = t.slowest.max(start.elapsed());
        let failure = match result.map(|r| r.and_then(|got| verdict(&intact, &got))) {
            Err(_) => {
                t.panics += 1;
                Some("panicked".to_owned())
            }
            Ok(Ok(true)) => {
                t.reported += 1;
                None
            }
            Ok(Ok(false)) => {
                t.identical += 1;
                None
            }
            Ok(Err(e)) => {
                t.different += 1;
                Some(e)
            }
        };
        if let Some(e) = failure
            && out.failures.len() < 10
        {
            out.failures.push(format!("{name}, case {i} ({kind:?}: {what}): {e}"));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    out
}

/// The table of campaigns by tool and kind of damage.
pub fn table(rows: &[(&str, &Campaign)]) -> String {
    let mut s = format!(
        "{:<12} {:<9} {:>7} {:>9} {:>9} {:>9} {:>7} {:>9}\n",
        "tool", "damage", "cases", "reported", "identical", "different", "panics", "slowest"
    );
    for (name, c) in rows {
        let total = c.total();
        for (kind, t) in
            c.by_kind.iter().map(|(k, t)| (format!("{k:?}"), *t)).chain([("all".to_owned(), total)])
        {
            s += &format!(
                "{name:<12} {kind:<9} {:>7} {:>9} {:>9} {:>9} {:>7} {:>7.1}ms\n",
                t.cases,
                t.reported,
                t.identical,
                t.different,
                t.panics,
                t.slowest.as_secs_f64() * 1e3
            );
        }
    }
    s
}

/// Asserts a campaign kept every promise: no panic, no other answer than the intact file's
/// without damage reported.
pub fn assert_kept(name: &str, c: &Campaign) {
    let t = c.total();
    assert!(t.panics == 0 && t.different == 0, "{name}: {t:?}\n{}", c.failures.join("\n"));
    assert!(t.reported > 0, "{name}: no damage was ever reported");
}
