//! Tests of the condition files: merging into a world, and the refusals naming file, line, key.

use super::*;

const HALLWAY: &str = include_str!("../../../worlds/hallway.toml");

fn condition(text: &str) -> Condition {
    Condition::parse(text, Path::new("c/my.toml")).expect("parses")
}

fn refusal(text: &str) -> String {
    condition(text).apply(HALLWAY, "hallway.toml").expect_err("refused").to_string()
}

#[test]
fn an_empty_condition_leaves_the_world_text_as_it_is() {
    let c = condition("# nothing\n");
    assert!(c.is_empty());
    assert_eq!(c.name, "my");
    assert_eq!(c.apply(HALLWAY, "hallway.toml").expect("applies"), HALLWAY);
}

#[test]
fn overrides_replace_world_fields_and_keep_the_rest() {
    let c = condition("[camera]\nillumination = 170.0\nnoise_sd = 8\nvignetting = 0.35\n");
    let merged = c.apply(HALLWAY, "hallway.toml").expect("applies");
    let w = harvey_world::load_str(&merged, "merged").expect("loads");
    let orig = harvey_world::load_str(HALLWAY, "hallway").expect("loads");
    assert_eq!((w.camera.illumination, w.camera.noise_sd, w.camera.vignetting), (170.0, 8.0, 0.35));
    assert_eq!(w.camera.focal_px, orig.camera.focal_px);
    assert_eq!(w.walls.len(), orig.walls.len());
    assert_eq!((w.start.x_m, w.start.y_m), (orig.start.x_m, orig.start.y_m));
    // A dotted key reaches the same field.
    let d = condition("camera.noise_sd = 3.5\n").apply(HALLWAY, "hallway.toml").expect("applies");
    assert_eq!(harvey_world::load_str(&d, "d").expect("loads").camera.noise_sd, 3.5);
}

#[test]
fn an_unknown_key_is_named_with_its_file_and_line() {
    let e = refusal("# no fisheye model\n[camera]\nnoise_sd = 2\nfisheye = 1.5\n");
    assert!(e.starts_with("c/my.toml:4: key `camera.fisheye`"), "{e}");
    let e = refusal("[camra]\nnoise_sd = 2\n");
    assert!(e.starts_with("c/my.toml:1: key `camra`"), "{e}");
}

#[test]
fn values_out_of_range_are_named_with_their_file_and_line() {
    let e = refusal("[camera]\nnoise_sd = -1\n");
    assert!(e.starts_with("c/my.toml:2: key `camera.noise_sd`"), "{e}");
    let e = refusal("[camera]\nnoise_sd = 1\n\nvignetting = 1.0\n");
    assert!(e.starts_with("c/my.toml:4: key `camera.vignetting`"), "{e}");
    let e = refusal("[camera]\nillumination = \"bright\"\n");
    assert!(e.starts_with("c/my.toml:2: key `camera.illumination`"), "{e}");
}

#[test]
fn a_syntax_error_names_its_line() {
    let e =
        Condition::parse("[camera]\nnoise_sd = = 2\n", Path::new("c/my.toml")).expect_err("bad").to_string();
    assert!(e.starts_with("c/my.toml:2:"), "{e}");
}

#[test]
fn the_shipped_conditions_apply_to_every_shipped_world() {
    for name in ["nominal", "dim", "harsh"] {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("conditions").join(format!("{name}.toml"));
        let c = Condition::load(&file).expect("loads");
        for world in ["hallway", "dock", "arena", "campus", "room"] {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds").join(format!("{world}.toml"));
            let text = std::fs::read_to_string(&path).expect("world");
            c.apply(&text, world).unwrap_or_else(|e| panic!("{name} on {world}: {e}"));
        }
    }
}

#[test]
fn names_resolve_to_the_conditions_folder() {
    let mission = Path::new(env!("CARGO_MANIFEST_DIR")).join("missions/default.toml");
    let p = resolve("dim", &mission).expect("found");
    assert!(p.ends_with("conditions/dim.toml"), "{}", p.display());
    let e = resolve("no-such-condition", &mission).expect_err("unknown").to_string();
    assert!(e.contains("no condition `no-such-condition`"), "{e}");
}
