//! The mutation harness over the shipped missions' `[mission]` tables: seeded mutants (a number
//! made impossible or an edge value, a key deleted, a table duplicated, the text cut short) are
//! parsed and, when accepted, built into an executive in the mission's world; none may panic, and
//! every impossible number must be refused with an error naming the file and its line or key.
//! (`[launch]` and `[[service]]` are the supervisor's harness, `[[mover]]` the world crate's.)
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

#[path = "../../../crates/world/tests/mutate/mod.rs"]
mod mutate;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use harvey_executive::{mission, setup};
use harvey_geometry::Rng;
use harvey_world::World;
use mutate::{Change, Number, always_impossible, leaf, mutate, names_place};

/// Keys of `[mission]` that take no zero: times, sizes, ranges, speeds, gains of turns, counts.
const POSITIVE: &[&str] = &[
    "timeout_s",
    "increment_m",
    "aim_m",
    "template_px",
    "prior_sd",
    "gate_px",
    "max_sd_m",
    "approach_m",
    "door_depth_m",
    "milestone_m",
    "goal_tolerance_m",
    "escalate_m",
    "attempts",
    "back_off_m",
    "frame_width_m",
    "target_side_m",
    "hough_range_m",
    "retry_after_m",
    "lead_m",
    "keep_in_view_deg",
    "close_area_px",
    "fix_gate_m",
    "fix_gate_deg",
    "post_height_sd_px",
    "heading_drift_deg_per_m",
    "final_m",
    "ballistic_mps",
    "controlled_mps",
    "max_turn_degps",
    "turn_gain",
    "avoid_sphere_m",
    "count",
    "sweep_deg",
    "centred_deg",
    "wander_s",
    "ring_contrast",
    "near_m",
    "park_m",
    "lost_m",
    "past_cell_m",
];

/// Keys that may be zero but take no negative number: spreads, heights above the floor, grey
/// levels, fractions, schema gains, waits, tick counts.
const NON_NEGATIVE: &[&str] = &[
    "hough_range_sd_m",
    "hough_band_min_m",
    "fix_beyond_m",
    "too_close_m",
    "frame_height_m",
    "target_height_m",
    "target_grey",
    "hough_min_certainty",
    "fix_every_ticks",
    "noise_ticks",
    "noise_mps",
    "avoid_gain",
    "probe_gain",
    "past_gain",
    "past_decay",
    "enough",
    "timer_slack_s",
    "beacon_wait_s",
    "back_off_s",
    "lost_after_s",
];

/// Whether `value` at `n` is outside every range the key may have. Positions, headings, moves,
/// turns, offsets and scores take 0 and -1.
fn impossible(n: &Number, value: &str) -> bool {
    let key = leaf(&n.key);
    match value {
        "0" => POSITIVE.contains(&key),
        "-1" => POSITIVE.contains(&key) || NON_NEGATIVE.contains(&key),
        _ => always_impossible(value),
    }
}

/// `text` with every line outside the `[mission]` tables blanked, so that lines keep their
/// numbers and only the mission is mutated.
fn mission_only(text: &str) -> String {
    let (mut inside, mut depth) = (false, 0i64);
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        let t = line.trim_start();
        if depth == 0 && t.starts_with('[') && !t.contains('=') {
            inside = t.trim_start_matches('[').starts_with("mission");
        } else {
            depth += open_brackets(line);
        }
        out.push_str(if inside { line } else { "\n" });
    }
    out
}

/// Brackets opened minus closed on `line`, outside strings and comments (a multi-line array's
/// rows are not headers).
fn open_brackets(line: &str) -> i64 {
    let (mut depth, mut quoted) = (0, false);
    for b in line.bytes() {
        match b {
            b'"' => quoted = !quoted,
            b'#' if !quoted => break,
            b'[' if !quoted => depth += 1,
            b']' if !quoted => depth -= 1,
            _ => {}
        }
    }
    depth
}

/// A shipped mission: its path, `[mission]` text and world.
struct Shipped {
    path: PathBuf,
    name: String,
    text: String,
    world: World,
}

fn shipped() -> Vec<Shipped> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../missions");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("missions/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter(|p| !p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|path| {
            let full = std::fs::read_to_string(&path).expect("mission");
            let doc: toml::Table = toml::from_str(&full).expect("TOML");
            let world = doc["launch"]["world"].as_str().expect("launch.world");
            let world = World::load(&dir.join(world)).expect("the mission's world");
            let name = format!("missions/{}", path.file_name().unwrap().to_string_lossy());
            Shipped { path, name, text: mission_only(&full), world }
        })
        .collect()
}

/// What a mutant came to: `None` when parsed and built, else the error.
fn load(mutant: &str, m: &Shipped) -> Option<String> {
    let file = m.path.display().to_string();
    match mission::parse(mutant, &file) {
        Err(e) => Some(e.to_string()),
        Ok(parsed) => setup::executive(&parsed, &m.path, Some(&m.world), 1).err().map(|e| e.to_string()),
    }
}

#[test]
fn mutated_missions_never_panic_and_refuse_every_impossible_number_by_name() {
    let files = shipped();
    assert!(files.len() >= 10, "the shipped missions");
    let started = Instant::now();
    let mut rng = Rng::new(14);
    let (mut cases, mut refused, mut checked) = (0, 0, 0);
    let (mut panics, mut accepted, mut unnamed) = (Vec::new(), Vec::new(), Vec::new());
    for m in &files {
        for case in 0..120 {
            let (mutant, change) = mutate(&m.text, &mut rng);
            cases += 1;
            let what = format!("{} case {case}: {change:?}", m.name);
            let Ok(result) = catch_unwind(AssertUnwindSafe(|| load(&mutant, m))) else {
                panics.push(what);
                continue;
            };
            refused += usize::from(result.is_some());
            if let Change::Number { number, value } = &change
                && impossible(number, value)
            {
                checked += 1;
                match &result {
                    None => accepted.push(what),
                    Some(e) if !names_place(e, &m.name, number) => unnamed.push(format!("{what}: {e}")),
                    Some(_) => {}
                }
            }
        }
    }
    let took = started.elapsed();
    eprintln!("missions: {cases} cases, {refused} refused, {checked} impossible numbers, {took:?}");
    assert!(cases >= 1000, "only {cases} cases");
    assert!(checked >= 300, "only {checked} impossible numbers");
    assert!(panics.is_empty(), "{} panics: {:#?}", panics.len(), &panics[..panics.len().min(5)]);
    assert!(accepted.is_empty(), "{} impossible values accepted: {accepted:#?}", accepted.len());
    assert!(unnamed.is_empty(), "refusals that name neither line nor key: {unnamed:#?}");
    assert!(took < Duration::from_secs(10), "{took:?}: a hang?");
}

#[test]
fn only_the_mission_is_kept_and_its_lines_keep_their_numbers() {
    let text = "[launch]\nname = \"x\"\n[mission]\ntimeout_s = 1\n[[service]]\nx = [\n  [2],\n]\n\
                [[mission.step]]\nmove_m = 1\n[mission.refine]\nv = [\n  [1.0],\n]\n";
    let want = "\n\n[mission]\ntimeout_s = 1\n\n\n\n\n[[mission.step]]\nmove_m = 1\n[mission.refine]\nv = [\n  [1.0],\n]\n";
    assert_eq!(mission_only(text), want);
}
