//! Validation at the door for the `[mission]` table: every number finite and in its range, lists
//! capped, refusals naming the file, the line and the key; the shipped missions still load, and
//! the checks of how a table's numbers fit together keep their messages. Each test of a kind of
//! refusal failed before the ranges (the value was accepted).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use std::path::Path;

use harvey_executive::{mission, setup};
use harvey_world::World;

const DEFAULT: &str = include_str!("../../../missions/default.toml");
const DOCKING: &str = include_str!("../../../missions/docking.toml");
const POLES: &str = include_str!("../../../missions/poles.toml");
// The hand-listed form: its vertices are reached into below (`missions/ptrans.toml` selects them).
const PTRANS: &str = include_str!("../../../missions/ptrans-listed.toml");
const SERVOED: &str = include_str!("../../../missions/hallway-40ft.toml");

/// `text` with its first `from` replaced by `to` (which must be there).
fn with(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from:?} is not in the mission");
    text.replacen(from, to, 1)
}

/// The error of parsing `text` as `m.toml`.
fn refusal(text: &str) -> String {
    mission::parse(text, "m.toml").expect_err("refused").to_string()
}

/// The 1-based line of `text` that holds `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).expect("the line") + 1
}

#[test]
fn a_timeout_that_never_comes_is_refused_by_file_line_and_key() {
    let line = line_of(DEFAULT, "timeout_s");
    let e = refusal(&with(DEFAULT, "timeout_s = 60.0", "timeout_s = inf"));
    assert_eq!(
        e,
        format!("m.toml:{line}: key `mission.timeout_s`: inf is not a finite number in (0, 86400] s")
    );
    let e = refusal(&with(DEFAULT, "timeout_s = 60.0", "timeout_s = 1e308"));
    assert!(e.ends_with("key `mission.timeout_s`: 1e308 is outside (0, 86400] s"), "{e}");
}

#[test]
fn steps_refuse_huge_moves_and_turns_and_impossible_increments_and_offsets() {
    let e = refusal(&with(DEFAULT, "move_m = 4.0", "move_m = 1e308"));
    assert!(e.contains("key `mission.step[0].move_m`: 1e308 is outside [-20000, 20000] m"), "{e}");
    let e = refusal(&with(DEFAULT, "turn_deg = 180.0", "turn_deg = -1e300"));
    assert!(e.contains("key `mission.step[1].turn_deg`"), "{e}");
    let e = refusal(&with(SERVOED, "increment_m = 0.6096", "increment_m = 1e-300"));
    assert!(e.contains("key `mission.step[0].increment_m`: 1e-300 is outside [0.001, 20000] m"), "{e}");
    let e = refusal(&with(SERVOED, "servo_vertex_m = [0.0, 0.2, 0.1]", "servo_vertex_m = [0.0, inf, 0.1]"));
    let line = line_of(SERVOED, "servo_vertex_m");
    assert!(e.starts_with(&format!("m.toml:{line}: key `mission.step[0].servo_vertex_m[1]`: inf")), "{e}");
    let offset = with(DEFAULT, "move_m = 4.0", "refine_pose = true\nbelief_offset_m = [nan, 0.0]");
    let refine = "[mission.refine]\nvertices_m = [[1.0, 1.0, 1.0], [2.0, 1.0, 1.0]]\ntemplate_px = 16\n\
                  min_score = 0.9\nprior_sd = [0.3, 0.3, 3.0]\ngate_px = 3.0\n";
    let e = refusal(&format!("{offset}{refine}"));
    assert!(e.contains("key `mission.step[0].belief_offset_m[0]`: NaN is not a finite number"), "{e}");
}

#[test]
fn the_servo_and_refine_tables_refuse_what_no_camera_or_correlation_can_do() {
    let e = refusal(&with(SERVOED, "min_score = 0.9", "min_score = nan"));
    assert!(e.contains("key `mission.servo.min_score`: NaN is not a finite number in [-1, 1]"), "{e}");
    let e = refusal(&with(SERVOED, "misalignment_deg = 0.0", "misalignment_deg = 1e300"));
    assert!(e.contains("key `mission.servo.misalignment_deg`"), "{e}");
    let e = refusal(&with(SERVOED, "template_px = 16", "template_px = 100000"));
    assert!(e.contains("key `mission.servo.template_px`: 100000 is outside [4, 1024] px"), "{e}");
    let e = refusal(&with(PTRANS, "template_px = 16", "template_px = 0"));
    let line = line_of(PTRANS, "template_px");
    assert_eq!(e, format!("m.toml:{line}: key `mission.refine.template_px`: 0 is outside [4, 1024] px"));
    let e = refusal(&with(PTRANS, "prior_sd = [0.3, 0.3, 3.0]", "prior_sd = [0.3, 0.0, 3.0]"));
    assert!(e.contains("key `mission.refine.prior_sd[1]`: 0 is outside (0, 20000] m"), "{e}");
    let e = refusal(&with(PTRANS, "gate_px = 3.0", "gate_px = inf"));
    assert!(e.contains("key `mission.refine.gate_px`"), "{e}");
    // A vertex deep in a multi-line array is named by its own line and indices.
    let e = refusal(&with(PTRANS, "[12.2, 1.0, 1.7]", "[12.2, 1.0, -inf]"));
    let line = line_of(PTRANS, "[12.2, 1.0, 1.7]");
    assert!(e.starts_with(&format!("m.toml:{line}: key `mission.refine.vertices_m[4][2]`: -inf")), "{e}");
}

#[test]
fn goal_tables_refuse_numbers_their_checks_let_through() {
    let e = refusal(&with(PTRANS, "goal_heading_deg = 60.0", "goal_heading_deg = 1e308"));
    assert!(e.contains("key `mission.ptrans.goal_heading_deg`: 1e308 is outside [-720, 720] deg"), "{e}");
    let e = refusal(&with(PTRANS, "attempts = 3", "attempts = 4000000000"));
    assert!(e.contains("key `mission.ptrans.attempts`: 4000000000 is outside [1, 1000]"), "{e}");
    let e = refusal(&with(DOCKING, "keep_in_view_deg = 15.0", "keep_in_view_deg = -1"));
    let line = line_of(DOCKING, "keep_in_view_deg");
    assert_eq!(
        e,
        format!("m.toml:{line}: key `mission.docking.keep_in_view_deg`: -1 is outside (0, 180] deg")
    );
    let e = refusal(&with(DOCKING, "light_contrast = 1.3", "light_contrast = nan"));
    assert!(e.contains("key `mission.docking.light_contrast`"), "{e}");
    let e = refusal(&with(DOCKING, "hough_range_sd_m = 1.22", "hough_range_sd_m = inf"));
    assert!(e.contains("key `mission.docking.hough_range_sd_m`"), "{e}");
    let e = refusal(&with(POLES, "avoid_gain = 0.4", "avoid_gain = nan"));
    assert!(e.contains("key `mission.poles.avoid_gain`: NaN is not a finite number in [0, 10] m/s"), "{e}");
    let e = refusal(&with(POLES, "count = 10", "count = 4000000000"));
    assert!(e.contains("key `mission.poles.count`: 4000000000 is outside [1, 100] poles"), "{e}");
    let e = refusal(&with(POLES, "timer_slack_s = 8.0", "timer_slack_s = 1e308"));
    assert!(e.contains("key `mission.poles.timer_slack_s`"), "{e}");
}

#[test]
fn lists_and_the_description_are_capped() {
    let steps = "[[mission.step]]\nturn_deg = 1.0\n".repeat(10_001);
    let e = refusal(&format!("[mission]\ndescription = \"d\"\ntimeout_s = 60\n{steps}"));
    assert!(e.contains("key `mission.step[10000]`: 10001 steps, more than the 10000 allowed"), "{e}");
    let vertices = "[1.0, 1.0, 1.0], ".repeat(1_001);
    let e = refusal(&with(PTRANS, "vertices_m = [\n", &format!("vertices_m = [{vertices}\n")));
    assert!(e.contains("key `mission.refine.vertices_m[1000]`: 1039 vertices, more than the 1000"), "{e}");
    let long = "x".repeat(10_001);
    let e = refusal(&with(DEFAULT, "description = \"", &format!("description = \"{long}")));
    assert!(e.contains("key `mission.description`: "), "{e}");
}

#[test]
fn the_checks_of_how_numbers_fit_together_keep_their_messages() {
    let e = refusal(&with(PTRANS, "escalate_m = 0.5", "escalate_m = 0.1"));
    assert_eq!(e, "m.toml: mission.ptrans: escalate_m must exceed milestone_m and goal_tolerance_m");
    let e = refusal(&with(POLES, "enough = 9", "enough = 11"));
    assert!(e.ends_with("count at least 1, enough at most count, lost_m and near_m beyond park_m"), "{e}");
    let e = refusal(&with(DOCKING, "too_close_m = 0.3", "too_close_m = 0.6"));
    assert!(e.ends_with("hough_min_certainty must be in 0..1 and too_close_m under final_m"), "{e}");
    let e = refusal(&with(DOCKING, "target_grey = [0.0, 15.0]", "target_grey = [15.0, 0.0]"));
    assert!(e.ends_with("target_grey must be two grey levels, low then high"), "{e}");
    let e = refusal(&with(DEFAULT, "turn_deg = 180.0", "turn_deg = 180.0\nmove_m = 1.0"));
    assert!(e.starts_with("m.toml: mission.step[1] needs exactly one finite"), "{e}");
    let e = refusal(&with(DEFAULT, "turn_deg = 180.0", "turn_deg = 180.0\nincrement_m = 0.5"));
    assert_eq!(e, "m.toml: mission.step[1].increment_m must be positive, on a move");
}

/// The world a shipped launch file names (`[launch] world`, relative to `missions/`).
fn world_of(path: &Path, text: &str) -> World {
    let doc: toml::Table = toml::from_str(text).expect("TOML");
    let world = doc["launch"]["world"].as_str().expect("launch.world");
    World::load(&path.parent().expect("missions/").join(world)).expect("the world")
}

#[test]
fn every_shipped_mission_still_loads_and_builds_in_its_world() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../missions");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("missions/") {
        let path = entry.expect("entry").path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.extension().is_none_or(|e| e != "toml") || name.starts_with('.') {
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("readable");
        let world = world_of(&path, &text);
        let m = mission::parse(&text, &name).unwrap_or_else(|e| panic!("{name}: {e}"));
        setup::executive(&m, &path, Some(&world), 1).unwrap_or_else(|e| panic!("{name}: {e}"));
        n += 1;
    }
    assert!(n >= 10, "only {n} missions");
}
