//! A class I landmark's predicted look (000 §5.3's ray-traced appearance, for a line), sent with
//! its window: the step across its line in four bands of the window's rows, kept only where
//! every pose the map allows predicts the same polarity.

use harvey_world::{Landmark, Pose2, World};

use crate::expecter::Window;
use crate::geometry::Pt;
use crate::map::Map;

/// The landmark's look through `win`: the step across its line (`harvey_render::edge_contrast`)
/// as the map's centre, the pose the robot believes, predicts it. A band whose step another pose
/// of the map (the polygon's vertices nearest, farthest and to either side of the landmark at
/// the believed heading, or the centre at either limit of the heading wedge) predicts of the
/// other sign, or as nothing, is 0: the map does not tell which
/// way the step runs there (the line's top against a lintel seen from one side, a door's far
/// side seen through it). All 0 when the line's foot is not in front of the camera.
pub fn look(world: &World, map: &Map, size: (u32, u32), l: &Landmark, win: &Window) -> [f32; 4] {
    let centre = Pose2 { x_m: map.centre[0], y_m: map.centre[1], heading_rad: map.heading_rad };
    let seen = |pose: Pose2| {
        let [u, _] = world.camera.project(size.0, size.1, pose, l.position_m)?;
        Some(harvey_render::edge_contrast(world, pose, size, u, [win.v0, win.v1]))
    };
    let Some(mut look) = seen(centre) else { return [0.0; 4] };
    let others = extremes(map, l.position_m)
        .map(|p| Pose2 { x_m: p[0], y_m: p[1], ..centre })
        .into_iter()
        .chain([-map.cw_rad, map.ccw_rad].map(|d| Pose2 { heading_rad: map.heading_rad + d, ..centre }));
    // A pose traced already tells nothing new (an exact map's vertices and wedge are its centre).
    let (mut traced, mut n) = ([centre; 7], 1);
    for pose in others {
        if traced[..n].contains(&pose) {
            continue;
        }
        (traced[n], n) = (pose, n + 1);
        let other = seen(pose).unwrap_or([0.0; 4]);
        for (c, o) in look.iter_mut().zip(other) {
            if *c * o <= 0.0 {
                *c = 0.0;
            }
        }
    }
    look
}

/// The polygon's vertices nearest and farthest from the landmark and farthest to either side of
/// the line to it: where its view changes most (a map can have dozens of vertices).
fn extremes(map: &Map, at: [f64; 3]) -> [Pt; 4] {
    let (dx, dy) = (at[0] - map.centre[0], at[1] - map.centre[1]);
    let along = |p: &Pt| (p[0] - map.centre[0]) * dx + (p[1] - map.centre[1]) * dy;
    let across = |p: &Pt| (p[1] - map.centre[1]) * dx - (p[0] - map.centre[0]) * dy;
    let pick = |key: &dyn Fn(&Pt) -> f64, most: bool| {
        let by = |a: &&Pt, b: &&Pt| key(a).total_cmp(&key(b));
        let p = if most { map.polygon.iter().max_by(by) } else { map.polygon.iter().min_by(by) };
        p.copied().unwrap_or(map.centre)
    };
    [pick(&along, false), pick(&along, true), pick(&across, false), pick(&across, true)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expecter::{View, window};
    use crate::tests::hallway;

    fn landmark<'w>(w: &'w World, name: &str) -> &'w Landmark {
        w.landmarks.iter().find(|l| l.name == name).expect("landmark")
    }

    #[test]
    fn a_known_pose_predicts_the_jambs_opposite_steps() {
        let w = hallway();
        let view = View { camera: &w.camera, width_px: 640, height_px: 480 };
        let map = Map::exact(0.0, 0.0, 0.0);
        let step = |name: &str| {
            let l = landmark(&w, name);
            let win = window(&map, view, l, 4.0).expect("in view");
            look(&w, &map, (640, 480), l, &win)
        };
        let (west, east) = (step("lab-door-west-jamb"), step("lab-door-east-jamb"));
        // The corridor's wall (0.70) against the lab through the door (0.50): down to the right
        // at the west jamb, up at the east one, in the bands beside the door.
        assert!(west.iter().any(|&c| c < -0.1) && west.iter().all(|&c| c <= 0.0), "west {west:?}");
        assert!(east.iter().any(|&c| c > 0.1) && east.iter().all(|&c| c >= 0.0), "east {east:?}");
    }

    #[test]
    fn a_band_the_map_cannot_tell_the_polarity_of_is_zero() {
        let w = hallway();
        let view = View { camera: &w.camera, width_px: 640, height_px: 480 };
        let l = landmark(&w, "lab-door-east-jamb");
        // One window (the rows the recogniser will read) for every map.
        let win = window(&Map::exact(2.5, 0.0, 0.0), view, l, 4.0).expect("in view");
        let at = |map: &Map| look(&w, map, (640, 480), l, &win);
        // Down the hall, 1.5 and 3.5 m from its west end: beside the door both see the lab
        // (0.50) left of the jamb and the corridor's wall (0.70) right of it, but the window's top
        // and bottom rows see other things from the two (the lintel, the baseboard, the floor).
        let (far, near) = (at(&Map::exact(1.5, 0.0, 0.0)), at(&Map::exact(3.5, 0.0, 0.0)));
        assert!(far[0] < 0.0 && near[0] > 0.0 && far[3] < 0.0 && near[3] > 0.0, "{far:?} {near:?}");
        // The centre alone predicts a step in every band.
        let centre = at(&Map::exact(2.5, 0.005, 0.0));
        assert!(centre.iter().all(|&c| c != 0.0), "{centre:?}");
        // A map 2 m long down the hall (dead reckoning's along a long leg): beside the door the
        // look is kept, the top and bottom bands are not.
        let long = Map::region(&[[1.5, 0.0], [3.5, 0.0], [3.5, 0.01], [1.5, 0.01]], 0.0, 0.01, 0.01);
        let vague = at(&long);
        assert_eq!((vague[0], vague[3]), (0.0, 0.0), "{vague:?}");
        assert!(vague[1..3].iter().all(|&c| (c - 0.2).abs() < 1e-6), "{vague:?}");
        // A wedge that turns the line out of view from one of its limits: nothing is predicted.
        let turned = Map { ccw_rad: std::f64::consts::PI, ..Map::exact(2.5, 0.0, 0.0) };
        assert_eq!(at(&turned), [0.0; 4]);
    }
}
