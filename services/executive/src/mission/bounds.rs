//! The range of every number of a `[mission]` table, and caps on its lists: checked when the
//! table is parsed, before the checks of how its parts fit together (`mod.rs`, `goals.rs`) and
//! before the executive uses a number. Each range is stated where it is checked, with why; the
//! shipped missions sit well inside all of them. The goal tables' ranges are in `bounds_goals.rs`.

use super::{Mission, Refine, Servo, Step};
use harvey_config::range::{OutOfRange, Range, check, check_all, check_int, check_len};
use harvey_config::spans::KeyPath;

/// The longest a mission may run: a day of simulated time. The shipped missions give 60 to
/// 1200 s; `inf` or 1e308 never times out, so a stuck mission would never end.
pub(crate) const TIMEOUT: Range = Range::above(0.0, 86_400.0, "s");
/// Positions in the world (goals, the dock, vertices): the world's own range, 10 km either way
/// from its origin.
pub(crate) const POSITION: Range = Range::within(10_000.0, "m");
/// Distances the executive works with (approach, tolerances, ranges, gates): positive and no
/// longer than the world is wide. A zero tolerance or range is never met.
pub(crate) const LENGTH: Range = Range::above(0.0, 20_000.0, "m");
/// Distances that may be zero (spreads, a clearance left out).
pub(crate) const LENGTH_OR_ZERO: Range = Range::closed(0.0, 20_000.0, "m");
/// Headings and turns: two full turns either way, as the world's headings.
pub(crate) const ANGLE: Range = Range::within(720.0, "deg");
/// A move, either way: across the widest world (20 km).
const MOVE: Range = Range::within(20_000.0, "m");
/// A move's increment: at least a millimetre, below which the drive cannot resolve it and a
/// move becomes millions of increments.
const INCREMENT: Range = Range::closed(0.001, 20_000.0, "m");
/// Offsets from a landmark's point or from odometry's pose: a room's size, 100 m either way.
const OFFSET: Range = Range::within(100.0, "m");
/// The camera's yaw from the direction of motion: beyond 90 degrees it looks backwards.
const MISALIGNMENT: Range = Range::within(90.0, "deg");
/// A correlation score (normalised cross-correlation lies in -1..1).
const SCORE: Range = Range::closed(-1.0, 1.0, "");
/// How well the expected pose is known: positive spreads (a zero spread divides by zero), up to
/// the world's width and half a turn.
const PRIOR_SD_M: Range = Range::above(0.0, 20_000.0, "m");
const PRIOR_SD_DEG: Range = Range::above(0.0, 180.0, "deg");
/// A gate on a vertex's image position: positive, up to the diagonal of the largest image the
/// world's camera renders (4096 x 4096 px).
const GATE_PX: Range = Range::above(0.0, 5_793.0, "px");
/// A correlation template's side: at least 4 pixels (the servo's existing check), at most 1024,
/// a quarter of the largest image (the vision service correlates side x side pixels per place).
pub(crate) const TEMPLATE_MIN_PX: u32 = 4;
pub(crate) const TEMPLATE_MAX_PX: u32 = 1_024;

/// Steps a script may hold (the executive keeps them all, and their servo set-ups); the shipped
/// missions have up to ten.
pub(crate) const MAX_STEPS: usize = 10_000;
/// Vertices plan-level servoing may look for (each is a correlation search on every refinement);
/// the shipped missions have up to 38.
pub(crate) const MAX_VERTICES: usize = 1_000;
/// The longest description (it is logged and recorded): a few paragraphs.
pub(crate) const MAX_DESCRIPTION: usize = 10_000;

/// The key path `mission.<key>`.
pub(crate) fn root(key: &'static str) -> KeyPath {
    KeyPath::default().key("mission").key(key)
}

/// Every number of `m` finite and in its range, every list within its cap.
pub(crate) fn check_bounds(m: &Mission) -> Result<(), OutOfRange> {
    let chars = m.description.chars().count();
    if chars > MAX_DESCRIPTION {
        let detail = format!("{chars} characters, more than the {MAX_DESCRIPTION} allowed");
        return Err(OutOfRange { key: root("description"), detail });
    }
    check(&root("timeout_s"), m.timeout_s, &TIMEOUT)?;
    check_len(&root("step"), m.steps.len(), MAX_STEPS, "steps")?;
    for (i, s) in m.steps.iter().enumerate() {
        check_step(&root("step").index(i), s)?;
    }
    if let Some(sv) = &m.servo {
        check_servo(&root("servo"), sv)?;
    }
    if let Some(r) = &m.refine {
        check_refine(&root("refine"), r)?;
    }
    if let Some(p) = &m.ptrans {
        super::bounds_goals::check_ptrans(&root("ptrans"), p)?;
    }
    if let Some(d) = &m.docking {
        super::bounds_goals::check_docking(&root("docking"), d)?;
    }
    if let Some(p) = &m.poles {
        super::bounds_goals::check_poles(&root("poles"), p)?;
    }
    if let Some(n) = &m.neptune {
        super::bounds_goals::check_neptune(&root("neptune"), n)?;
    }
    if let Some(d) = &m.door {
        super::door::check_bounds(&root("door"), d)?;
    }
    if let Some(p) = &m.path {
        super::path::check_bounds(&root("path"), p)?;
    }
    if let Some(d) = &m.depth {
        super::depth::check_bounds(&root("depth"), d)?;
    }
    Ok(())
}

fn check_step(k: &KeyPath, s: &Step) -> Result<(), OutOfRange> {
    if let Some(v) = s.move_m {
        check(&k.key("move_m"), v, &MOVE)?;
    }
    if let Some(v) = s.turn_deg {
        check(&k.key("turn_deg"), v, &ANGLE)?;
    }
    if let Some(v) = s.increment_m {
        check(&k.key("increment_m"), v, &INCREMENT)?;
    }
    check_all(&k.key("servo_vertex_m"), &s.servo_vertex_m, &OFFSET)?;
    if let Some(b) = &s.belief_offset_m {
        check_all(&k.key("belief_offset_m"), b, &OFFSET)?;
    }
    Ok(())
}

fn check_servo(k: &KeyPath, s: &Servo) -> Result<(), OutOfRange> {
    check(&k.key("aim_m"), s.aim_m, &LENGTH)?;
    check(&k.key("misalignment_deg"), s.misalignment_deg, &MISALIGNMENT)?;
    check(&k.key("gate_deg"), s.gate_deg, &Range::above(0.0, 90.0, "deg"))?;
    check(&k.key("gate_range"), s.gate_range, &Range::above(0.0, 10.0, ""))?;
    check_int(&k.key("template_px"), s.template_px, TEMPLATE_MIN_PX, TEMPLATE_MAX_PX, "px")?;
    check(&k.key("min_score"), s.min_score, &SCORE)
}

fn check_refine(k: &KeyPath, r: &Refine) -> Result<(), OutOfRange> {
    check_len(&k.key("vertices_m"), r.vertices_m.len(), MAX_VERTICES, "vertices")?;
    for (i, v) in r.vertices_m.iter().enumerate() {
        check_all(&k.key("vertices_m").index(i), v, &POSITION)?;
    }
    check_int(&k.key("template_px"), r.template_px, TEMPLATE_MIN_PX, TEMPLATE_MAX_PX, "px")?;
    check(&k.key("min_score"), r.min_score, &SCORE)?;
    check_all(&k.key("prior_sd"), &r.prior_sd[..2], &PRIOR_SD_M)?;
    check(&k.key("prior_sd").index(2), r.prior_sd[2], &PRIOR_SD_DEG)?;
    check(&k.key("gate_px"), r.gate_px, &GATE_PX)?;
    if let Some(v) = r.max_sd_m {
        check(&k.key("max_sd_m"), v, &LENGTH)?;
    }
    if let Some(c) = r.select_contrast {
        // A reflectance step: above nothing (every region would do), at most a whole one.
        check(&k.key("select_contrast"), c, &Range::above(0.0, 1.0, ""))?;
    }
    Ok(())
}
