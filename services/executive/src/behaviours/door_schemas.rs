//! Door finding's motor schemas (001 §3.2's second way, the schema-based system of its Chapter
//! 8): each echo within the sphere of influence repels (avoid-static-obstacle), move-ahead
//! presses the robot along the wall and into it; the wall's push counterbalances the press, and
//! "when the door opening appears, the obstacle avoidance pressure lessens and the robot moves
//! into the doorway". Once the schemas' sum has turned `drawn_in_deg` towards the wall over
//! `drawn_for_m` of travel (after the robot has slid along the wall, pushed back, over the fit's
//! window), the robot is in the opening: move-ahead then presses straight
//! through, the jambs' echoes centring it.

use harvey_geometry::wrap;

use super::door_finding::{DoorFinding, LEFT, RIGHT};
use super::drive;
use super::schemas::V2;
use super::wall::Line;

/// Where the slide stands: whether the wall has been held (the press counterbalanced by its
/// push over the fit's window), the travel it has been held over and the travel at the last tick
/// it was; the travel since which the sum has been drawn towards the wall.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Slide {
    pub felt_wall: bool,
    pub held_m: f64,
    pub held_since_m: Option<f64>,
    pub drawn_since_m: Option<f64>,
}

fn unit(a: f64) -> V2 {
    V2::new(a.cos(), a.sin())
}

/// avoid-static-obstacle over the ring's echoes (none before the first ring).
fn avoid(d: &DoorFinding) -> V2 {
    d.ring.as_ref().map_or(V2::default(), |r| drive::avoid_echoes(r, d.at, d.ring_m, &d.drive))
}

/// Sliding along the wall as located (the press's direction: a robot pressed in at a slant reads
/// slant ranges, which a line fit would take for the wall turning; only the line's offset is
/// kept up, from side readings taken nearly square to it), the three schemas summed and driven.
pub(crate) fn slide(d: &mut DoorFinding, parts: &mut [V2; 5]) -> (f64, f64) {
    let here = [d.at.x_m, d.at.y_m];
    keep_wall_offset(d, here, 12f64.to_radians());
    let along = d.wall.line.along(d.side);
    let into = wrap(along + d.side * std::f64::consts::FRAC_PI_2);
    parts[0] = unit(along).scale(d.g.along_mps);
    parts[1] = unit(into).scale(d.g.press_mps);
    parts[2] = avoid(d);
    let u = unit(into);
    let pushed = -parts[2].dot(u) >= d.g.press_mps / 2.0;
    let sum = drive::vectors(*parts, &d.drive).sum;
    let turned = d.side * wrap(sum.y.atan2(sum.x) - along);
    let drawn = sum.norm() > 1e-6 && turned >= d.g.drawn_in_deg.to_radians();
    // The wall is held once the robot has slid along it, pushed back and not drawn in, over the
    // fit's window all told (coming up to the wall, the press still turns the sum towards it;
    // a lost echo now and then lets the push lapse for a reading).
    if pushed && !drawn && !d.slide.felt_wall {
        let since = *d.slide.held_since_m.get_or_insert(d.travelled_m);
        d.slide.held_m += d.travelled_m - since;
        d.slide.felt_wall = d.slide.held_m >= d.g.fit_m;
    }
    d.slide.held_since_m = (pushed && !drawn).then_some(d.travelled_m);
    // Drawn in over `drawn_for_m` of travel (a lost echo or two beside the wall turn the sum
    // for a moment).
    let drawn_from = match (d.slide.felt_wall && drawn, d.slide.drawn_since_m) {
        (true, Some(from)) => Some(from),
        (true, None) => Some(d.travelled_m),
        (false, _) => None,
    };
    d.slide.drawn_since_m = drawn_from;
    if drawn_from.is_some_and(|from| d.travelled_m - from >= d.g.drawn_for_m) {
        tracing::info!(x_m = here[0], y_m = here[1], "drawn into the opening");
        let length = d.wall.line.distance(here) + d.g.through_m;
        // The doorway counted, and where the robot was drawn in (its middle is not measured).
        d.openings += 1;
        d.door = Some(here);
        d.enter(here, into, length);
        return (0.0, 0.0);
    }
    drive::velocity(sum, d.at, &d.drive)
}

/// The schemas' wall: its offset moved to the side sensor's new reading, when the robot is
/// within `square_rad` of the wall's direction (the reading then the perpendicular distance)
/// and the reading lies within the loose gate of the line.
pub(crate) fn keep_wall_offset(d: &mut DoorFinding, here: [f64; 2], square_rad: f64) {
    let mut stamp = d.side_stamp;
    let sensor = if d.side > 0.0 { LEFT } else { RIGHT };
    let Some(reading) = d.fresh(sensor, &mut stamp) else { return };
    d.side_stamp = stamp;
    let square = wrap(d.at.heading_rad - d.wall.line.along(d.side)).abs() <= square_rad;
    if let Some(r) = reading.filter(|&r| square && d.wall.fits(here, r)) {
        d.wall.line = Line::seen_from(here, d.wall.line.normal_rad, r);
    }
}

/// Through the doorway: move-ahead along `heading`, the jambs repelling.
pub(crate) fn press(d: &DoorFinding, heading: f64, parts: &mut [V2; 5]) -> (f64, f64) {
    parts[1] = unit(heading).scale(d.g.press_mps);
    parts[2] = avoid(d);
    drive::velocity(drive::vectors(*parts, &d.drive).sum, d.at, &d.drive)
}
