//! Blunder rejection among one frame's sightings (after Gennery's residual editing, 003, and
//! 002 §5.2's confirmation before a reduction): the bearings of several landmarks seen in the
//! same frame each imply the robot's heading; a sighting whose implied heading disagrees with
//! the others' median by more than its own spread (times the UMS's sigmas) is a false match (an
//! Expecter window holding another landmark's edge) and is not applied. One wrong reduction
//! would otherwise cut the truth out of the map for good.

use harvey_msgs::{LandmarkSighting, SightingKind};
use harvey_world::World;

use crate::map::Map;

/// Whether a bearing sighting is implausible on its own: its bearing differs from the one the
/// map's most likely pose predicts by more than `sigmas` times its spread (its own and the
/// landmark's place seen from here) plus all the map's heading wedge and position spread can
/// move it. The reduction slices by the polygon's edges and the wedge apart; this bounds the
/// sighting against the most likely pose as a whole.
pub fn implausible(world: &World, map: &Map, s: &LandmarkSighting, sigmas: f64) -> bool {
    let bearing =
        matches!(SightingKind::from_raw(s.kind), Some(SightingKind::Bearing | SightingKind::BearingRange));
    let Some(l) = world.landmarks.get(s.landmark_index as usize).filter(|_| bearing) else { return false };
    let (dx, dy) = (l.position_m[0] - map.centre[0], l.position_m[1] - map.centre[1]);
    let d = dx.hypot(dy).max(0.1);
    let predicted = harvey_geometry::wrap(dy.atan2(dx) - map.heading_rad);
    let innovation = harvey_geometry::wrap(s.a - predicted);
    // A heading further counter-clockwise turns every bearing clockwise: a bearing short of
    // the prediction is what the wedge's counter-clockwise side explains, and the other way on.
    let wedge = if innovation < 0.0 { map.ccw_rad } else { map.cw_rad };
    let spread = s.a_sd.hypot(world.landmark_sd_m(l) / d);
    innovation.abs() > sigmas * spread + wedge + radius(map) / d
}

/// The map's farthest vertex from its centre.
fn radius(map: &Map) -> f64 {
    map.polygon.iter().map(|p| (p[0] - map.centre[0]).hypot(p[1] - map.centre[1])).fold(0.0, f64::max)
}

/// The indices into `group` (sightings of one frame) that disagree with the rest, and every
/// pair of different landmarks seen on one edge (`same_edge`); the majority is told from three
/// bearings on.
pub fn outliers(world: &World, map: &Map, group: &[LandmarkSighting], sigmas: f64) -> Vec<usize> {
    let mut out = same_edge(group);
    for i in majority(world, map, group, sigmas) {
        if !out.contains(&i) {
            out.push(i);
        }
    }
    out
}

/// One edge, one landmark: two landmarks' bearings in one frame within a fifth of the sharper
/// one's spread (a fraction of a pixel) are one edge two windows took, a look-alike for one of
/// them at least, which of them the frame cannot tell: both indices, in `group`'s order.
fn same_edge(group: &[LandmarkSighting]) -> Vec<usize> {
    let bearing = |s: &LandmarkSighting| {
        matches!(SightingKind::from_raw(s.kind), Some(SightingKind::Bearing | SightingKind::BearingRange))
    };
    (0..group.len())
        .filter(|&i| {
            let a = &group[i];
            bearing(a)
                && group.iter().any(|b| {
                    bearing(b)
                        && b.landmark_index != a.landmark_index
                        && harvey_geometry::wrap(a.a - b.a).abs() < 0.2 * a.a_sd.min(b.a_sd)
                })
        })
        .collect()
}

/// The indices into `group` whose implied heading disagrees with the others' median; empty
/// with fewer than three bearings, where a majority cannot be told.
fn majority(world: &World, map: &Map, group: &[LandmarkSighting], sigmas: f64) -> Vec<usize> {
    // (index, implied heading, (its spread, the shift the map's spread may give it))
    let mut implied: Vec<(usize, f64, (f64, f64))> = Vec::new();
    // How far the map's own spread of positions moves a bearing: its farthest vertex.
    let radius =
        map.polygon.iter().map(|p| (p[0] - map.centre[0]).hypot(p[1] - map.centre[1])).fold(0.0, f64::max);
    for (i, s) in group.iter().enumerate() {
        let bearing = matches!(
            SightingKind::from_raw(s.kind),
            Some(SightingKind::Bearing | SightingKind::BearingRange)
        );
        let Some(l) = world.landmarks.get(s.landmark_index as usize).filter(|_| bearing) else { continue };
        let (dx, dy) = (l.position_m[0] - map.centre[0], l.position_m[1] - map.centre[1]);
        let d = dx.hypot(dy).max(0.1);
        let spread = s.a_sd.hypot(world.landmark_sd_m(l) / d);
        implied.push((i, harvey_geometry::wrap(dy.atan2(dx) - s.a), (spread, radius / d)));
    }
    if implied.len() < 3 {
        return Vec::new();
    }
    // Against the median sighting: the two spreads add as independent errors, while the map's
    // own spread moves near and far bearings apart and enters both in full.
    let mut by_heading = implied.clone();
    by_heading.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (_, median, (median_spread, median_shift)) = by_heading[by_heading.len() / 2];
    implied
        .into_iter()
        .filter(|&(_, h, (spread, shift))| {
            harvey_geometry::wrap(h - median).abs()
                > sigmas * spread.hypot(median_spread) + shift + median_shift
        })
        .map(|(i, ..)| i)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::Header;

    #[test]
    fn the_one_that_disagrees_with_the_others_is_the_blunder() {
        let w =
            harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads");
        let map = Map::exact(0.0, 0.0, 0.0);
        let seen = |name: &str, error_rad: f64| {
            let (i, l) = w.landmarks.iter().enumerate().find(|(_, l)| l.name == name).expect("a landmark");
            let truth = l.position_m[1].atan2(l.position_m[0]);
            LandmarkSighting {
                header: Header::new(1, 100),
                landmark_index: i as u32,
                kind: SightingKind::Bearing as u32,
                a: truth + error_rad,
                a_sd: 0.004,
                ..Default::default()
            }
        };
        // Two jambs a few mrad off (the map and the mount), the end-wall corner 40 mrad off
        // (its window held the office door's jamb).
        let frame = [
            seen("lab-door-west-jamb", 0.008),
            seen("lab-door-east-jamb", 0.006),
            seen("end-wall-corner", 0.040),
        ];
        assert_eq!(outliers(&w, &map, &frame, 3.0), vec![2]);
        assert!(outliers(&w, &map, &frame[..2], 3.0).is_empty(), "two cannot outvote each other");
        let agreeing = [frame[0], frame[1], seen("end-wall-corner", 0.004)];
        assert!(outliers(&w, &map, &agreeing, 3.0).is_empty());
        // Alone, with the pose known to a few mrad: 40 mrad off is implausible, 6 is not.
        let known =
            Map::region(&[[-0.01, -0.01], [0.01, -0.01], [0.01, 0.01], [-0.01, 0.01]], 0.0, 0.005, 0.005);
        assert!(implausible(&w, &known, &frame[2], 3.0));
        assert!(!implausible(&w, &known, &frame[1], 3.0));
        // A wide wedge (a long turn) lets more through.
        let turned = Map { cw_rad: 0.06, ccw_rad: 0.06, ..known.clone() };
        assert!(!implausible(&w, &turned, &frame[2], 3.0));
        // A lopsided wedge lets through only the bearings its wide side explains: the robot
        // may be turned up to 60 mrad counter-clockwise, which puts the corner 40 mrad
        // clockwise of (short of) where the wedge's heading sees it, not 40 mrad beyond.
        let lopsided = Map { cw_rad: 0.001, ccw_rad: 0.06, ..known.clone() };
        let short = LandmarkSighting { a: frame[2].a - 0.080, ..frame[2] };
        assert!(!implausible(&w, &lopsided, &short, 3.0));
        assert!(implausible(&w, &lopsided, &frame[2], 3.0));
        let mirrored = Map { cw_rad: 0.06, ccw_rad: 0.001, ..known };
        assert!(implausible(&w, &mirrored, &short, 3.0));
        assert!(!implausible(&w, &mirrored, &frame[2], 3.0));
    }

    #[test]
    fn two_landmarks_on_one_edge_are_both_refused() {
        let w =
            harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads");
        let map = Map::exact(0.0, 0.0, 0.0);
        let at = |i: u32, a: f64| LandmarkSighting {
            header: Header::new(1, 100),
            landmark_index: i,
            kind: SightingKind::Bearing as u32,
            a,
            a_sd: 0.004,
            ..Default::default()
        };
        // The end-wall corner's window held the office door's jamb: both on the same column,
        // the jamb's sighting right, the corner's 37 mrad off. Two: no majority, both refused.
        let (jamb, corner) = (at(2, 0.0379), at(5, 0.0379 + 0.0002));
        assert_eq!(outliers(&w, &map, &[jamb, corner], 3.0), vec![0, 1]);
        // A pixel apart (1.8 mrad at 554 px): two edges.
        assert!(outliers(&w, &map, &[jamb, at(5, 0.0379 + 0.0018)], 3.0).is_empty());
        // The same landmark twice (two recognisers) is not two landmarks.
        assert!(outliers(&w, &map, &[jamb, at(2, 0.0379)], 3.0).is_empty());
    }
}
