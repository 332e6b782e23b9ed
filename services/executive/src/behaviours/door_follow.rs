//! Door finding's first way (001 §3.2): follow the wall at an even distance, the side sensor's
//! new readings kept on the wall's fit and watched for its openings; a door-sized opening
//! counted, and the wanted one's middle backed to once the wall is found again.

use super::door_finding::{DoorFinding, LEFT, Phase, RIGHT};
use super::opening::Event;
use super::wall::steer;

/// Wall following: steer for the kept distance; on the side sensor's new readings, track
/// the wall and its openings; the door's middle once the wanted opening has closed.
pub(crate) fn follow(d: &mut DoorFinding, here: [f64; 2]) -> (f64, f64) {
    let mut side_stamp = d.side_stamp;
    let sensor = if d.side > 0.0 { LEFT } else { RIGHT };
    if let Some(range) = d.fresh(sensor, &mut side_stamp) {
        d.side_stamp = side_stamp;
        let event = d.opening.reading(&mut d.wall, here, d.travelled_m, range);
        if let Event::Closed { from, to } = event {
            closed(d, from, to);
        }
    }
    let heading = if d.opening.is_open() {
        d.wall.line.along(d.side)
    } else {
        let g = &d.g;
        let line = d.wall.line;
        steer(
            &line,
            d.at,
            d.side,
            g.keep_m,
            g.approach_deg_per_m.to_radians(),
            g.max_approach_deg.to_radians(),
        )
    };
    match d.phase {
        Phase::Following => d.hold(d.g.speed_mps, heading),
        _ => (0.0, 0.0),
    }
}

/// An opening from `from` to `to`: a door if its width is a door's; the wanted one is taken.
fn closed(d: &mut DoorFinding, from: [f64; 2], to: [f64; 2]) {
    let along = d.wall.line.along(d.side);
    let width = (to[0] - from[0]) * along.cos() + (to[1] - from[1]) * along.sin();
    let [least, most] = d.g.door_width_m;
    tracing::info!(width_m = width, "an opening in the wall");
    if width < least || width > most {
        return;
    }
    d.openings += 1;
    if d.openings == d.g.opening {
        let mid = [(from[0] + to[0]) / 2.0, (from[1] + to[1]) / 2.0];
        d.door = Some(mid);
        d.go(Phase::Backing { to: mid, along });
    }
}
