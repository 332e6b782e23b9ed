//! Plan sketches for plan-and-monitor (000 §2, §4): a goal `(ptrans a b)` between places is
//! decomposed depth-first over the world's locale graph (locales joined by doorways) into a
//! sketch `(M0 (ptrans a x) M1 (ptrans x b) Mg)`, refined only at its front: the leading
//! subgoal is split at the first doorway of its route until it stays inside one locale, where it
//! is primitive (a TURN then a MOVE). The back stays abstract until execution reaches it.

use harvey_world::World;

/// A place the plan passes: a point on the floor and the locale it is in.
#[derive(Debug, Clone, PartialEq)]
pub struct Place {
    pub name: String,
    pub at: [f64; 2],
    pub locale: String,
}

/// One subgoal of a sketch, between milestones `from` and `to`.
#[derive(Debug, Clone, PartialEq)]
pub struct Ptrans {
    pub from: Place,
    pub to: Place,
    /// Inside one locale: executable as a TURN then a MOVE.
    pub primitive: bool,
}

/// Why no plan could be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("no locale {0} in the world")]
    UnknownLocale(String),
    #[error("no route of doorways from {0} to {1}")]
    NoRoute(String, String),
    #[error("gave up at milestone {0}, last known at {1:.2?} m")]
    GaveUp(String, [f64; 2]),
}

/// The doorways (indices into `world.doors`) leading from locale `from` to `to`, found
/// depth-first (000 §2), never entering a locale twice.
pub fn route(world: &World, from: &str, to: &str) -> Result<Vec<usize>, PlanError> {
    for l in [from, to] {
        if !world.locales.iter().any(|x| x.name == l) {
            return Err(PlanError::UnknownLocale(l.to_owned()));
        }
    }
    fn dfs(world: &World, at: &str, to: &str, seen: &mut Vec<String>, path: &mut Vec<usize>) -> bool {
        if at == to {
            return true;
        }
        seen.push(at.to_owned());
        for (i, d) in world.doors.iter().enumerate() {
            let next = match (&d.between[0], &d.between[1]) {
                (a, b) if a == at => b,
                (a, b) if b == at => a,
                _ => continue,
            };
            if seen.iter().any(|s| s == next) {
                continue;
            }
            path.push(i);
            if dfs(world, next, to, seen, path) {
                return true;
            }
            path.pop();
        }
        false
    }
    let mut path = Vec::new();
    if dfs(world, from, to, &mut Vec::new(), &mut path) {
        Ok(path)
    } else {
        Err(PlanError::NoRoute(from.to_owned(), to.to_owned()))
    }
}

/// Points `depth_m` either side of doorway `i`, along the normal of the wall it is in:
/// `[in a, in b]` for its `between = [a, b]`.
fn door_sides(world: &World, i: usize, depth_m: f64) -> [[f64; 2]; 2] {
    let d = &world.doors[i];
    // The wall the doorway is cut in: the one whose line passes nearest its centre.
    let off_line = |w: &harvey_world::Wall| {
        let (ux, uy) = (w.to[0] - w.from[0], w.to[1] - w.from[1]);
        let len = ux.hypot(uy).max(1e-9);
        ((d.at[0] - w.from[0]) * uy - (d.at[1] - w.from[1]) * ux).abs() / len
    };
    let (ux, uy) = world
        .walls
        .iter()
        .min_by(|a, b| off_line(a).total_cmp(&off_line(b)))
        .map_or((1.0, 0.0), |w| (w.to[0] - w.from[0], w.to[1] - w.from[1]));
    let len = ux.hypot(uy).max(1e-9);
    let n = [-uy / len, ux / len];
    let side = |sign: f64| [d.at[0] + sign * depth_m * n[0], d.at[1] + sign * depth_m * n[1]];
    let in_a = world
        .locales
        .iter()
        .find(|l| l.name == d.between[0])
        .is_some_and(|l| harvey_world::topology::contains(&l.outline, side(1.0)));
    if in_a { [side(1.0), side(-1.0)] } else { [side(-1.0), side(1.0)] }
}

/// Refines the sketch's leading non-primitive subgoal one level: split at the first doorway of
/// its route, through a place just inside each side of it. Returns whether anything changed.
pub fn refine_front(world: &World, sketch: &mut Vec<Ptrans>, depth_m: f64) -> Result<bool, PlanError> {
    let Some(k) = sketch.iter().position(|p| !p.primitive) else { return Ok(false) };
    let p = sketch[k].clone();
    if p.from.locale == p.to.locale {
        sketch[k].primitive = true;
        return Ok(true);
    }
    let doors = route(world, &p.from.locale, &p.to.locale)?;
    let i = doors[0];
    let d = &world.doors[i];
    let sides = door_sides(world, i, depth_m);
    let (near, far) = if d.between[0] == p.from.locale { (0, 1) } else { (1, 0) };
    let here = Place {
        name: format!("{}-side-of-door-{i}", p.from.locale),
        at: sides[near],
        locale: p.from.locale.clone(),
    };
    let other = d.between[far].clone();
    let there = Place { name: format!("{other}-side-of-door-{i}"), at: sides[far], locale: other };
    sketch.splice(
        k..=k,
        [
            Ptrans { from: p.from, to: here.clone(), primitive: false },
            // Through the doorway: a straight crossing, primitive by construction.
            Ptrans { from: here, to: there.clone(), primitive: true },
            Ptrans { from: there, to: p.to, primitive: false },
        ],
    );
    Ok(true)
}

/// Refines the front until it is primitive (the back may stay abstract).
pub fn refine_leading(world: &World, sketch: &mut Vec<Ptrans>, depth_m: f64) -> Result<(), PlanError> {
    while sketch.first().is_some_and(|p| !p.primitive) {
        refine_front(world, sketch, depth_m)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hallway() -> World {
        harvey_world::load_str(include_str!("../../../../worlds/hallway.toml"), "hallway").expect("world")
    }

    fn place(name: &str, at: [f64; 2], locale: &str) -> Place {
        Place { name: name.into(), at, locale: locale.into() }
    }

    #[test]
    fn routes_go_depth_first_through_doorways() {
        let w = hallway();
        assert_eq!(route(&w, "robot-lab", "teds-office"), Ok(vec![0, 1]));
        assert_eq!(route(&w, "hallway", "hallway"), Ok(vec![]));
        assert_eq!(route(&w, "robot-lab", "attic"), Err(PlanError::UnknownLocale("attic".into())));
        // `grc` is a grouping with no doorway of its own.
        assert_eq!(route(&w, "robot-lab", "grc"), Err(PlanError::NoRoute("robot-lab".into(), "grc".into())));
    }

    #[test]
    fn the_sketch_is_detailed_at_the_front_and_abstract_at_the_back() {
        let w = hallway();
        let start = place("bench", [5.0, 4.0], "robot-lab");
        let goal = place("desk", [12.0, 3.5], "teds-office");
        let mut sketch = vec![Ptrans { from: start, to: goal.clone(), primitive: false }];
        refine_leading(&w, &mut sketch, 0.6).expect("plans");
        // (bench -> lab side of the lab door) primitive, the door crossing primitive, and the
        // rest, hallway -> desk, still one abstract subgoal.
        assert_eq!(sketch.len(), 3);
        assert!(sketch[0].primitive && sketch[1].primitive && !sketch[2].primitive);
        assert_eq!(sketch[0].to.at, [4.45, 1.6]);
        assert_eq!(sketch[1].to.at, [4.45, 0.4]);
        assert_eq!((sketch[2].from.locale.as_str(), sketch[2].to.clone()), ("hallway", goal));
        // Execution reaches the back: it is refined in turn, through the office door.
        sketch.drain(..2);
        refine_leading(&w, &mut sketch, 0.6).expect("plans");
        let points: Vec<[f64; 2]> = sketch.iter().map(|p| p.to.at).collect();
        assert_eq!(points, vec![[11.45, 0.4], [11.45, 1.6], [12.0, 3.5]]);
        assert!(sketch[0].primitive && sketch[1].primitive && !sketch[2].primitive);
        // The last subgoal stays in the office: refining it makes it primitive, and then
        // nothing is left to refine.
        sketch.drain(..2);
        assert_eq!(refine_front(&w, &mut sketch, 0.6), Ok(true));
        assert!(sketch[0].primitive);
        assert_eq!(refine_front(&w, &mut sketch, 0.6), Ok(false));
    }
}
