//! The ranges and caps of a world's topology (locales, doors, meadows, landmarks) and of its
//! `[poles]`: the part of `bounds.rs` that is not walls, robot and camera.

use crate::bounds::{FRACTION, MAX_ITEMS, POLE_COUNT, POSITION};
use crate::{PoleField, World};
use harvey_config::range::{OutOfRange, Range, check, check_all, check_len};
use harvey_config::spans::KeyPath;

fn root(key: &'static str) -> KeyPath {
    KeyPath::default().key(key)
}

/// Each corner of the outline at `k` a position; at most [`MAX_ITEMS`] corners.
fn check_outline(k: &KeyPath, outline: &[[f64; 2]]) -> Result<(), OutOfRange> {
    check_len(k, outline.len(), MAX_ITEMS, "corners")?;
    outline.iter().enumerate().try_for_each(|(i, p)| check_all(&k.index(i), p, &POSITION))
}

pub(crate) fn check_topology_bounds(w: &World) -> Result<(), OutOfRange> {
    check_len(&root("locale"), w.locales.len(), MAX_ITEMS, "locales")?;
    for (i, l) in w.locales.iter().enumerate() {
        check_outline(&root("locale").index(i).key("outline"), &l.outline)?;
    }
    check_len(&root("door"), w.doors.len(), MAX_ITEMS, "doors")?;
    for (i, d) in w.doors.iter().enumerate() {
        let k = root("door").index(i);
        check_all(&k.key("at"), &d.at, &POSITION)?;
        check(&k.key("width_m"), d.width_m, &Range::above(0.0, 100.0, "m"))?;
    }
    check_len(&root("meadow"), w.meadows.len(), MAX_ITEMS, "meadows")?;
    for (i, m) in w.meadows.iter().enumerate() {
        let k = root("meadow").index(i);
        check_outline(&k.key("outline"), &m.outline)?;
        check_len(&k.key("landmarks"), m.landmarks.len(), MAX_ITEMS, "landmarks")?;
        if let Some(r) = &m.floor_reflectance {
            check_all(&k.key("floor_reflectance"), r, &FRACTION)?;
        }
    }
    check_len(&root("landmark"), w.landmarks.len(), MAX_ITEMS, "landmarks")?;
    for (i, l) in w.landmarks.iter().enumerate() {
        let k = root("landmark").index(i);
        check_all(&k.key("position_m"), &l.position_m, &POSITION)?;
        if let Some(to) = &l.to_m {
            check_all(&k.key("to_m"), to, &POSITION)?;
        }
        check(&k.key("height_m"), l.height_m, &Range::closed(0.0, 100.0, "m"))?;
        check(&k.key("position_sd_m"), l.position_sd_m, &Range::closed(0.0, 1_000.0, "m"))?;
        check(&k.key("activation_range_m"), l.activation_range_m, &Range::above(0.0, 20_000.0, "m"))?;
        check_all(&k.key("view_headings_deg"), &l.view_headings_deg, &Range::within(720.0, "deg"))?;
    }
    Ok(())
}

/// The `[poles]`: at most 100 (the AAAI-92 arena had 10; each is put down by up to 10 000 seeded
/// tries against every wall), sizes positive, a code step that tells codes apart.
pub(crate) fn check_poles(p: &PoleField) -> Result<(), OutOfRange> {
    let k = root("poles");
    let (size, height) = (Range::above(0.0, 100.0, "m"), Range::within(100.0, "m"));
    check(&k.key("count"), f64::from(p.count), &POLE_COUNT)?;
    p.area_m.iter().enumerate().try_for_each(|(i, c)| check_all(&k.key("area_m").index(i), c, &POSITION))?;
    check(&k.key("clearance_m"), p.clearance_m, &Range::closed(0.0, 1_000.0, "m"))?;
    check(&k.key("side_m"), p.side_m, &size)?;
    check(&k.key("height_m"), p.height_m, &size)?;
    check(&k.key("reflectance"), p.reflectance, &FRACTION)?;
    check(&k.key("ring_m"), p.ring_m, &size)?;
    check(&k.key("ring_reflectance"), p.ring_reflectance, &FRACTION)?;
    check(&k.key("top_m"), p.top_m, &height)?;
    check(&k.key("bottom_m"), p.bottom_m, &height)?;
    check(&k.key("code_base_m"), p.code_base_m, &height)?;
    // Codes are told apart by the middle ring's height over this step: zero would divide by it.
    check(&k.key("code_step_m"), p.code_step_m, &size)?;
    check(&k.key("visit_m"), p.visit_m, &Range::above(0.0, 1_000.0, "m"))
}
