//! Issue 20's defects in world files, each refused at the door with file, line and key: an
//! infinite terrain statistic (it panicked the UMS or grew it to 20 GB), a start at x = 1e308 (it
//! "reached" its goal), NaN beam widths and illumination, a pole count a service cannot place; and
//! every shipped world still loads.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

const HALLWAY: &str = include_str!("../../../worlds/hallway.toml");
const ARENA: &str = include_str!("../../../worlds/arena.toml");

/// Replaces the first `from` after the line containing `after` by `to`; the edited line's number.
fn edit(text: &str, after: &str, from: &str, to: &str) -> (String, usize) {
    let at = text.find(after).expect("anchor");
    let rel = text[at..].find(from).expect("value");
    let out = format!("{}{to}{}", &text[..at + rel], &text[at + rel + from.len()..]);
    let line = text[..at + rel].matches('\n').count() + 1;
    (out, line)
}

fn refused(text: &str) -> String {
    harvey_world::load_str(text, "w.toml").expect_err("must be refused").to_string()
}

#[test]
fn infinite_terrain_statistics_are_refused_with_line_and_key() {
    for (key, value, shown) in [
        ("rotational_loss_deg_per_deg", "inf", "inf"),
        ("drift_deg_per_ft", "inf", "inf"),
        ("drift_deg_per_ft", "1e300", "1e300"),
        ("skitter_sd_ft_per_deg", "nan", "NaN"),
        ("translational_loss_ft_per_ft", "-0.1", "-0.1"),
    ] {
        let (text, line) =
            edit(HALLWAY, "[terrain.tile]", &format!("{key} = "), &format!("{key} = {value} # "));
        let e = refused(&text);
        assert!(e.starts_with(&format!("w.toml:{line}: field `terrain.tile.{key}`: {shown}")), "{e}");
    }
}

#[test]
fn a_start_far_outside_any_world_is_refused() {
    let (text, line) = edit(HALLWAY, "[start]", "x_m = 0.0", "x_m = 1e308");
    let e = refused(&text);
    assert!(
        e.starts_with(&format!("w.toml:{line}: field `start.x_m`: 1e308 is outside [-10000, 10000] m")),
        "{e}"
    );
}

#[test]
fn nan_beam_widths_and_illumination_are_refused() {
    let (text, line) = edit(HALLWAY, "[robot]", "sonar_beam_width_deg = 30.0", "sonar_beam_width_deg = nan");
    let e = refused(&text);
    assert!(
        e.starts_with(&format!("w.toml:{line}: field `robot.sonar_beam_width_deg`: NaN is not a finite")),
        "{e}"
    );
    let (text, _) = edit(HALLWAY, "[robot]", "sonar_beam_width_deg = 30.0", "sonar_beam_width_deg = 90.0");
    assert!(refused(&text).contains("`robot.sonar_beam_width_deg`: 90 is outside (0, 90) deg"));
    let (text, line) = edit(HALLWAY, "[camera]", "illumination = 220.0", "illumination = nan");
    let e = refused(&text);
    assert!(e.starts_with(&format!("w.toml:{line}: field `camera.illumination`: NaN")), "{e}");
    let (text, line) = edit(HALLWAY, "[camera]", "vignetting = 0.2", "vignetting = 1.0");
    let e = refused(&text);
    assert!(e.starts_with(&format!("w.toml:{line}: field `camera.vignetting`")), "{e}");
}

#[test]
fn walls_regions_and_landmarks_name_their_element() {
    let (text, line) = edit(HALLWAY, "# notice board", "reflectance = 0.45", "reflectance = 1.5");
    let e = refused(&text);
    assert!(
        e.starts_with(&format!(
            "w.toml:{line}: field `wall[1].region[1].reflectance`: 1.5 is outside [0, 1]"
        )),
        "{e}"
    );
    let (text, line) = edit(HALLWAY, "name = \"office-sign\"", "[12.4, 1.0, 1.55]", "[12.4, -inf, 1.55]");
    let e = refused(&text);
    assert!(e.starts_with(&format!("w.toml:{line}: field `landmark[3].position_m[1]`: -inf")), "{e}");
}

#[test]
fn a_pole_count_no_service_could_place_is_refused() {
    let (text, line) = edit(ARENA, "[poles]", "count = 10", "count = 4000000000");
    let e = harvey_world::load_str(&text, "a.toml").expect_err("4e9 poles").to_string();
    assert!(
        e.starts_with(&format!("a.toml:{line}: field `poles.count`: 4000000000 is outside [0, 100] poles")),
        "{e}"
    );
    let (text, _) = edit(ARENA, "[poles]", "code_step_m = 0.07", "code_step_m = 0.0");
    assert!(
        harvey_world::load_str(&text, "a.toml")
            .expect_err("no step")
            .to_string()
            .contains("`poles.code_step_m`")
    );
}

#[test]
fn every_shipped_world_loads() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../worlds");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("worlds/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            harvey_world::World::load(&path).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert_eq!(n, 5);
}

#[test]
fn every_shipped_missions_movers_load() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../missions");
    let mut movers = 0;
    for entry in std::fs::read_dir(&dir).expect("missions/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            movers += harvey_world::load_movers(&path).unwrap_or_else(|e| panic!("{e}")).len();
        }
    }
    assert!(movers >= 2, "panic-avoid's cart and docking's movers: {movers}");
}

#[test]
fn movers_with_impossible_numbers_are_refused_with_line_and_key() {
    let cart = "[launch]\nname = \"x\"\n[[mover]]\nname = \"cart\"\noutline = [[-0.3, -0.25], [0.3, -0.25], [0.3, 0.25]]\nheight_m = 1.0\nreflectance = 0.3\npath = [[2.0, 10.0, 0.0], [12.0, 1e308, 0.0]]\n";
    let e = harvey_world::parse_movers(cart, "m.toml").expect_err("1e308 m").to_string();
    assert!(e.starts_with("m.toml:8: field `mover[0].path[1][1]`: mover cart: 1e308 is outside"), "{e}");
    let e = harvey_world::parse_movers(&cart.replace("height_m = 1.0", "height_m = nan"), "m.toml")
        .expect_err("NaN height")
        .to_string();
    assert!(e.starts_with("m.toml:6: field `mover[0].height_m`"), "{e}");
}
