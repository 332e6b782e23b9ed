//! What the map says a class III landmark (002 §3.4: a line on the ground plan) looks like to
//! the camera: the top edge of a band painted along a wall's foot (a baseboard), or the edge
//! where two floors of different reflectance meet (a path's edge against its lawn). Either way
//! an edge at a known height below the camera that steps one way going down an image column.

use harvey_world::{LandmarkClass, World};

/// How far either side of a line's middle (m) the floor is sampled for a floor edge.
const FLOOR_SIDE_M: f64 = 0.3;
/// Floors whose (checker-averaged) reflectances differ by less than this meet at no edge worth
/// looking for: a path's own checker steps by more.
const MIN_FLOOR_CONTRAST: f64 = 0.02;

/// What makes a class III landmark's line stand out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Edge {
    /// The top of a band painted along a wall's foot, and whether the band is darker than the
    /// wall above it: the wall is always the far side.
    Baseboard { darker: bool },
    /// Two floors meeting on the line: their reflectances (the checker's two values averaged)
    /// left and right of it, looking from its first end to its second. Which is the near side
    /// depends on the side the robot stands on.
    Floor { left: f64, right: f64 },
}

/// What the map says of a class III landmark's look.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band {
    /// The edge's height below the camera (m, positive): a band's top edge's, or the camera's
    /// own height for a floor edge.
    pub below_camera_m: f64,
    pub edge: Edge,
    /// How well the robot knows that height (m): the map's error for a band's top; for a floor
    /// edge (the floor is the datum) how well the camera's height over it is known, taken at
    /// the survey's accuracy.
    pub height_sd_m: f64,
}

impl Band {
    /// The class III landmarks of `world` along a wall's foot with a band painted from the floor
    /// (the lowest, on the first wall on the line), or failing a wall, on the floor where it
    /// changes across the line's middle, by index.
    pub fn of(world: &World) -> Vec<Option<Band>> {
        world
            .landmarks
            .iter()
            .map(|l| {
                let (LandmarkClass::III, Some(to)) = (l.class, l.to_m) else { return None };
                let a = l.position_m;
                let height_sd_m = world.survey.position_sd_m.max(l.position_sd_m);
                // Along a wall's foot: its lowest band standing on the floor, below the camera.
                let on_wall = world.wall_band(l).map(|(w, r)| Band {
                    below_camera_m: world.camera.height_m - r.height_m[1],
                    edge: Edge::Baseboard { darker: r.reflectance < w.reflectance },
                    height_sd_m,
                });
                on_wall.or_else(|| floor_edge(world, [a[0], a[1]], [to[0], to[1]], height_sd_m))
            })
            .collect()
    }

    /// Whether the image gets darker going down a column across the edge, for the robot standing
    /// on the line's right (`robot_right`, looking from its first end to its second) or on its
    /// left. Going down a column runs from the far side to the near.
    pub fn darker_below(&self, robot_right: bool) -> bool {
        match self.edge {
            Edge::Baseboard { darker } => darker,
            Edge::Floor { left, right } => {
                let (near, far) = if robot_right { (right, left) } else { (left, right) };
                near < far
            }
        }
    }
}

/// The floor edge on the line from `a` to `to`, if the floors either side of its middle differ.
fn floor_edge(world: &World, a: [f64; 2], to: [f64; 2], height_sd_m: f64) -> Option<Band> {
    let (dx, dy) = (to[0] - a[0], to[1] - a[1]);
    let len = dx.hypot(dy);
    if len <= 0.0 {
        return None;
    }
    let (mid, left) = ([(a[0] + to[0]) / 2.0, (a[1] + to[1]) / 2.0], [-dy / len, dx / len]);
    let at = |side: f64| {
        let r = world.floor_reflectance_at(mid[0] + side * left[0], mid[1] + side * left[1]);
        (r[0] + r[1]) / 2.0
    };
    let (l, r) = (at(FLOOR_SIDE_M), at(-FLOOR_SIDE_M));
    ((l - r).abs() >= MIN_FLOOR_CONTRAST).then_some(Band {
        below_camera_m: world.camera.height_m,
        edge: Edge::Floor { left: l, right: r },
        height_sd_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn world(name: &str, text: &str) -> World {
        harvey_world::load_str(text, name).expect("world")
    }

    #[test]
    fn the_campus_path_s_edges_are_floor_edges_and_the_hallway_keeps_its_baseboard() {
        let w = world("campus", include_str!("../../../../worlds/campus.toml"));
        let bands = Band::of(&w);
        // (landmark, path's checker, the lawn on its left): north edges have the lawn on their
        // left, south edges on their right.
        let lawn = (0.24 + 0.20) / 2.0;
        let (tile, concrete, gravel) = ((0.52 + 0.40) / 2.0, (0.56 + 0.53) / 2.0, (0.40 + 0.33) / 2.0);
        let expected = [
            ("path-north-edge", concrete, true),
            ("path-south-edge", concrete, false),
            ("bend-north-edge", gravel, true),
            ("bend-south-edge", gravel, false),
            ("east-north-edge", tile, true),
            ("east-south-edge", tile, false),
        ];
        for (name, path, lawn_left) in expected {
            let i = w.landmarks.iter().position(|l| l.name == name).expect("landmark");
            let b = bands[i].expect(name);
            let Edge::Floor { left, right } = b.edge else { panic!("{name}: {b:?}") };
            let (l, r) = if lawn_left { (lawn, path) } else { (path, lawn) };
            assert!((left - l).abs() < 1e-9 && (right - r).abs() < 1e-9, "{name}: {b:?}");
            assert!((b.below_camera_m - 1.2).abs() < 1e-9 && (b.height_sd_m - 0.01).abs() < 1e-12);
            // A lawn on the line's left: the robot on its right stands on the path, brighter going
            // down the column.
            assert!(!b.darker_below(lawn_left) && b.darker_below(!lawn_left), "{name}");
        }
        assert_eq!(bands.iter().filter(|b| b.is_some()).count(), 6);

        let w = world("hallway", include_str!("../../../../worlds/hallway.toml"));
        let bands = Band::of(&w);
        let i = w.landmarks.iter().position(|l| l.name == "north-baseboard").expect("landmark");
        let expected =
            Band { below_camera_m: 1.2 - 0.12, edge: Edge::Baseboard { darker: true }, height_sd_m: 0.01 };
        let b = bands[i].expect("the baseboard");
        assert!((b.below_camera_m - expected.below_camera_m).abs() < 1e-9, "{b:?}");
        assert_eq!(Band { below_camera_m: expected.below_camera_m, ..b }, expected);
        assert!(b.darker_below(true) && b.darker_below(false));
        assert!(bands.iter().enumerate().all(|(k, x)| k == i || x.is_none()));
    }
}
