//! The mutation harness over the shipped worlds and the missions' movers: seeded mutants of each
//! file (a number made impossible or an edge value, a key deleted, a table duplicated, the text
//! cut short) are loaded, and none may panic, and every impossible number must be refused with an
//! error naming the file and its line or key.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod mutate;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use harvey_geometry::Rng;
use mutate::{Change, Number, always_impossible, leaf, mutate, names_place};

/// Keys of a world or a mover that take no negative number.
const NON_NEGATIVE: &[&str] = &[
    "reflectance",
    "colour",
    "ceiling_reflectance",
    "floor_reflectance",
    "illumination",
    "vignetting",
    "noise_sd",
    "translational_loss_ft_per_ft",
    "inertial_loss_ft",
    "translational_sd_ft_per_ft",
    "drift_deg_per_ft",
    "drift_sd_deg_per_ft",
    "rotational_loss_deg_per_deg",
    "rotational_sd_deg_per_deg",
    "skitter_ft_per_deg",
    "skitter_sd_ft_per_deg",
    "width_px",
    "height_px",
    "focal_px",
    "speed_mps",
    "turn_rate_degps",
    "sonar_ring_radius_m",
    "sonar_beam_width_deg",
    "sonar_specular_limit_deg",
    "sonar_max_range_ft",
    "tile_m",
    "count",
    "clearance_m",
    "side_m",
    "ring_m",
    "ring_reflectance",
    "code_step_m",
    "visit_m",
    "activation_range_m",
    "position_sd_m",
    "width_m",
    "height_m",
];

/// Keys that take no zero (sizes, rates, ranges); `height_m` only where it is a size.
fn must_be_positive(key: &str, table: &str) -> bool {
    const POSITIVE: &[&str] = &[
        "width_px",
        "height_px",
        "focal_px",
        "speed_mps",
        "turn_rate_degps",
        "sonar_beam_width_deg",
        "sonar_specular_limit_deg",
        "sonar_max_range_ft",
        "tile_m",
        "side_m",
        "ring_m",
        "code_step_m",
        "visit_m",
        "activation_range_m",
        "width_m",
    ];
    POSITIVE.contains(&key) || (key == "height_m" && ["wall", "camera", "poles", "mover"].contains(&table))
}

/// Whether `value` at `n` is outside every range the key may have.
fn impossible(n: &Number, value: &str) -> bool {
    let key = leaf(&n.key);
    always_impossible(value)
        || (value == "-1" && NON_NEGATIVE.contains(&key))
        || (value == "0" && must_be_positive(key, &n.table))
}

fn shipped(dir: &str) -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(dir);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect(dir)
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|p| {
            (
                format!("{dir}/{}", p.file_name().unwrap().to_string_lossy()),
                std::fs::read_to_string(p).unwrap(),
            )
        })
        .collect()
}

/// What one kind of file came to.
#[derive(Default, Debug)]
struct Tally {
    cases: usize,
    panics: Vec<String>,
    accepted_impossible: Vec<String>,
    unnamed: Vec<String>,
    refused: usize,
}

/// Runs `per_file` mutants of each file through `load` (an error's text, or `None` when accepted),
/// only numbers `counts` for the oracle.
fn run(
    files: &[(String, String)],
    per_file: usize,
    seed: u64,
    counts: impl Fn(&Number) -> bool,
    load: impl Fn(&str, &str) -> Option<String>,
) -> Tally {
    let mut rng = Rng::new(seed);
    let mut t = Tally::default();
    for (name, text) in files {
        for case in 0..per_file {
            let (mutant, change) = mutate(text, &mut rng);
            t.cases += 1;
            let what = format!("{name} case {case}: {change:?}");
            let Ok(result) = catch_unwind(AssertUnwindSafe(|| load(&mutant, name))) else {
                t.panics.push(what);
                continue;
            };
            t.refused += usize::from(result.is_some());
            if let Change::Number { number, value } = &change
                && counts(number)
                && impossible(number, value)
            {
                match &result {
                    None => t.accepted_impossible.push(what),
                    Some(e) if !names_place(e, name, number) => t.unnamed.push(format!("{what}: {e}")),
                    Some(_) => {}
                }
            }
        }
    }
    t
}

fn assert_clean(kind: &str, t: &Tally, took: Duration) {
    eprintln!("{kind}: {} cases, {} refused, {:?}", t.cases, t.refused, took);
    assert!(t.cases >= 1000, "{kind}: only {} cases", t.cases);
    assert!(
        t.panics.is_empty(),
        "{kind}: {} panics: {:#?}",
        t.panics.len(),
        &t.panics[..t.panics.len().min(5)]
    );
    assert!(
        t.accepted_impossible.is_empty(),
        "{kind}: impossible values accepted: {:#?}",
        t.accepted_impossible
    );
    assert!(t.unnamed.is_empty(), "{kind}: refusals that name neither line nor key: {:#?}", t.unnamed);
    assert!(took < Duration::from_secs(20), "{kind}: {took:?}, a hang?");
}

#[test]
fn mutated_worlds_never_panic_and_refuse_every_impossible_number_by_name() {
    let files = shipped("worlds");
    assert_eq!(files.len(), 5, "the shipped worlds");
    let started = Instant::now();
    let t = run(
        &files,
        400,
        20,
        |_| true,
        |text, name| {
            match harvey_world::load_str(text, name) {
                Err(e) => Some(e.to_string()),
                Ok(mut w) => {
                    // What a service does first with a world: put its poles down (bounded work).
                    let _ = w.place_poles(1);
                    None
                }
            }
        },
    );
    assert_clean("worlds", &t, started.elapsed());
}

#[test]
fn mutated_movers_never_panic_and_refuse_every_impossible_number_by_name() {
    let files = shipped("missions");
    assert!(files.len() >= 10, "the shipped missions");
    let started = Instant::now();
    let t = run(
        &files,
        120,
        21,
        |n| n.table == "mover",
        |text, name| harvey_world::parse_movers(text, name).err().map(|e| e.to_string()),
    );
    assert_clean("movers", &t, started.elapsed());
}
