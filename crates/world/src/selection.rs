//! Landmark selection from the world model (000 §5.2): vertices where regions of differing
//! reflectance meet, that is the corners of the regions painted on walls (signs, doors, panels),
//! kept when they are in view from the expected pose, not hidden by a nearer wall, and
//! distinctive: the reflectance step across them is large. These are the points whose
//! appearance templates (the vision workers' `templates.rs`) correlation then finds; the
//! executive's plan-level servoing asks for them (`corners`) when a mission selects its vertices.
//! `Wall::local` places a point in a wall's frame (the recognisers find their landmark's paint).

use crate::{Pose2, World};

/// A selected vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vertex {
    pub point_m: [f64; 3],
    /// Where it should appear from the expected pose.
    pub image_px: [f64; 2],
    /// Reflectance of the region minus that of the wall round it (its sign tells which is
    /// lighter).
    pub contrast: f64,
    pub wall: usize,
}

impl crate::Wall {
    /// A point of the floor plan in the wall's frame: how far along it from `from`, and how far
    /// off its line, left of `from -> to` positive (m).
    pub fn local(&self, p: [f64; 2]) -> (f64, f64) {
        let len = self.length_m();
        let (dx, dy) = ((self.to[0] - self.from[0]) / len, (self.to[1] - self.from[1]) / len);
        let (rx, ry) = (p[0] - self.from[0], p[1] - self.from[1]);
        (rx * dx + ry * dy, ry * dx - rx * dy)
    }
}

/// Every vertex of the world where a painted region's corner meets its wall's paint with a
/// reflectance step of at least `min_contrast`, with the wall it is on: a region's corners off
/// the floor; where a region standing on the floor (a door) meets the top of a band along the
/// floor (a baseboard), that junction; and a floor band's top corner at its wall's end (a
/// doorway's edge, a corner of the room). Strongest first, then in the world file's order. The executive's plan-level servoing asks for those in view of each pose.
pub fn corners(world: &World, min_contrast: f64) -> Vec<([f64; 3], f64, usize)> {
    let mut out = Vec::new();
    for (i, w) in world.walls.iter().enumerate() {
        let len = w.length_m();
        if len <= 0.0 {
            continue;
        }
        let dir = [(w.to[0] - w.from[0]) / len, (w.to[1] - w.from[1]) / len];
        for r in &w.regions {
            let contrast = r.reflectance - w.reflectance;
            if contrast.abs() < min_contrast {
                continue;
            }
            // A band along the floor (a baseboard), lower than this region, whose top edge meets
            // this region's side.
            let band_top = |along: f64| {
                w.regions
                    .iter()
                    .filter(|b| b.height_m[0] <= 0.0 && b.height_m[1] < r.height_m[1])
                    .filter(|b| (b.along_m[0]..=b.along_m[1]).contains(&along))
                    .map(|b| b.height_m[1])
                    .next()
            };
            for along in r.along_m {
                let at_end = along <= 0.0 || along >= len;
                for z in r.height_m {
                    let z = match (z <= 0.0, at_end) {
                        // A band on the floor ends at its wall's end (a doorway, a corner): its
                        // top corner there is a vertex; its foot is not.
                        (false, true) if r.height_m[0] <= 0.0 => z,
                        (_, true) => continue,
                        // A region standing on the floor (a door) meets the band's top edge.
                        (true, false) => match band_top(along) {
                            Some(top) => top,
                            None => continue,
                        },
                        (false, false) => z,
                    };
                    if z >= w.height_m {
                        continue;
                    }
                    out.push(([w.from[0] + dir[0] * along, w.from[1] + dir[1] * along, z], contrast, i));
                }
            }
        }
    }
    // Strongest first; one vertex where two regions share a corner (a whiteboard and its frame's
    // shadow line), with the larger step.
    out.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    let mut kept: Vec<([f64; 3], f64, usize)> = Vec::with_capacity(out.len());
    for v in out {
        if !kept.iter().any(|k| (0..3).all(|i| (k.0[i] - v.0[i]).abs() < 1e-6)) {
            kept.push(v);
        }
    }
    kept
}

/// The vertices visible from `pose` in a `width x height` image, at least `margin_px` inside it,
/// within `range_m`, with a reflectance step of at least `min_contrast`; strongest first.
pub fn select(
    world: &World,
    pose: Pose2,
    [width, height]: [u32; 2],
    margin_px: f64,
    range_m: f64,
    min_contrast: f64,
) -> Vec<Vertex> {
    let mut out: Vec<Vertex> = corners(world, min_contrast)
        .into_iter()
        .filter_map(|(p, contrast, wall)| {
            let [u, v] = world.camera.project(width, height, pose, p)?;
            let inside = |a: f64, max: u32| a >= margin_px && a <= f64::from(max) - margin_px;
            let (dx, dy) = (p[0] - pose.x_m, p[1] - pose.y_m);
            let dist = dx.hypot(dy);
            if !inside(u, width) || !inside(v, height) || dist > range_m {
                return None;
            }
            // Nothing nearer on the way (the vertex's own wall is hit at its distance).
            let hit = world.cast_ray([pose.x_m, pose.y_m], [dx / dist, dy / dist], dist + 1.0);
            if hit.is_some_and(|h| h.distance_m < dist - 0.05) {
                return None;
            }
            Some(Vertex { point_m: p, image_px: [u, v], contrast, wall })
        })
        .collect();
    out.sort_by(|a, b| {
        b.contrast.abs().total_cmp(&a.contrast.abs()).then(a.image_px[0].total_cmp(&b.image_px[0]))
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hallway() -> World {
        crate::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads")
    }

    #[test]
    fn the_office_signs_corners_are_selected_in_view_and_hidden_ones_are_not() {
        let w = hallway();
        let pose = Pose2::new(8.0, 0.0, 0.3);
        let v = select(&w, pose, [640, 480], 16.0, 12.0, 0.15);
        assert!(!v.is_empty());
        // The red sign (x 12.2–12.6, z 1.4–1.7 on the north wall) is a strong vertex source.
        let sign: Vec<&Vertex> =
            v.iter().filter(|x| (12.1..12.7).contains(&x.point_m[0]) && x.point_m[1] > 0.9).collect();
        assert_eq!(sign.len(), 4, "{v:#?}");
        for x in &v {
            assert!(
                (16.0..=624.0).contains(&x.image_px[0]) && (16.0..=464.0).contains(&x.image_px[1]),
                "{x:?}"
            );
            assert!(x.contrast.abs() >= 0.15);
        }
        assert!(v.windows(2).all(|p| p[0].contrast.abs() >= p[1].contrast.abs()));
        // Looking the other way, the sign is behind the camera: not selected.
        let back = select(&w, Pose2::new(8.0, 0.0, std::f64::consts::PI), [640, 480], 16.0, 12.0, 0.15);
        assert!(back.iter().all(|x| x.point_m[0] < 8.0), "{back:#?}");
    }

    #[test]
    fn corners_take_in_the_doors_meeting_the_baseboard_and_the_doorways_edges() {
        let c: Vec<[f64; 3]> = corners(&hallway(), 0.15).into_iter().map(|(p, _, _)| p).collect();
        let has = |q: [f64; 3]| c.iter().any(|p| (0..3).all(|k| (p[k] - q[k]).abs() < 1e-9));
        // The closed door's foot where it meets the baseboard's top, the lab doorway's edges at the
        // baseboard's top, the exit sign's corner; nothing on the floor.
        for q in [[9.0, -1.0, 0.12], [8.1, -1.0, 0.12], [4.0, 1.0, 0.12], [4.9, 1.0, 0.12], [16.0, 0.2, 2.3]]
        {
            assert!(has(q), "{q:?} not in {c:?}");
        }
        assert!(c.iter().all(|p| p[2] > 0.0));
        // The whiteboard's lower corners are its frame's shadow line's upper ones: once each.
        let shared = c.iter().filter(|p| (p[0] - 14.0).abs() < 1e-9 && (p[2] - 0.9).abs() < 1e-9).count();
        assert_eq!(shared, 2, "{c:?}");
    }
}
