//! The mutation harness over the shipped missions as launch files: seeded mutants (a number made
//! impossible or an edge value, a key deleted, a table duplicated, the text cut short) are parsed,
//! none may panic, and every impossible number of `[launch]` or a `[[service]]` must be refused
//! with an error naming the file and its line or key. (`[mission]` is the executive's, `[[mover]]`
//! the world crate's harness.)
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

#[path = "../../world/tests/mutate/mod.rs"]
mod mutate;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::time::{Duration, Instant};

use harvey_geometry::Rng;
use harvey_supervisor::LaunchFile;
use mutate::{Change, Number, always_impossible, leaf, mutate, names_place};

/// Whether `value` at `n` is outside the key's range: every launch number is an unsigned
/// integer or a positive window; the seed takes any unsigned integer.
fn impossible(n: &Number, value: &str) -> bool {
    let key = leaf(&n.key);
    match value {
        "9223372036854775807" | "0" if key == "seed" => false,
        "0" => key != "max_restarts",
        "-1" => true,
        _ => always_impossible(value),
    }
}

#[test]
fn mutated_launch_files_never_panic_and_refuse_every_impossible_number_by_name() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../missions");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("missions/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 10, "the shipped missions");
    let started = Instant::now();
    let mut rng = Rng::new(22);
    let (mut cases, mut refused, mut checked) = (0, 0, 0);
    let (mut panics, mut accepted, mut unnamed) = (Vec::new(), Vec::new(), Vec::new());
    for path in &files {
        let text = std::fs::read_to_string(path).expect("mission");
        let name = format!("missions/{}", path.file_name().unwrap().to_string_lossy());
        for case in 0..120 {
            let (mutant, change) = mutate(&text, &mut rng);
            cases += 1;
            let what = format!("{name} case {case}: {change:?}");
            let parsed = catch_unwind(AssertUnwindSafe(|| {
                LaunchFile::parse(&mutant, Path::new(&name)).err().map(|e| e.to_string())
            }));
            let Ok(result) = parsed else {
                panics.push(what);
                continue;
            };
            refused += usize::from(result.is_some());
            if let Change::Number { number, value } = &change
                && (number.table == "launch" || number.table == "service")
                && impossible(number, value)
            {
                checked += 1;
                match &result {
                    None => accepted.push(what),
                    Some(e) if !names_place(e, &name, number) => unnamed.push(format!("{what}: {e}")),
                    Some(_) => {}
                }
            }
        }
    }
    let took = started.elapsed();
    eprintln!("launch files: {cases} cases, {refused} refused, {checked} impossible numbers, {took:?}");
    assert!(cases >= 1000, "only {cases} cases");
    assert!(panics.is_empty(), "{} panics: {:#?}", panics.len(), &panics[..panics.len().min(5)]);
    assert!(accepted.is_empty(), "impossible values accepted: {accepted:#?}");
    assert!(unnamed.is_empty(), "refusals that name neither line nor key: {unnamed:#?}");
    assert!(took < Duration::from_secs(20), "{took:?}: a hang?");
}
