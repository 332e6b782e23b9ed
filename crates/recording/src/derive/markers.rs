//! The markers the deriver draws: the world's walls and landmarks (once), the UMS's uncertainty
//! polygon and the executive's plan (each time they change), all in the `world` frame.

use harvey_cdr::{Colour, Marker, MarkerArray, MarkerKind, Point, Quaternion, frames};
use harvey_msgs::{PlanSketch, UncertaintyMap};
use harvey_world::World;

const WALL_THICKNESS_M: f64 = 0.04;
const LANDMARK_RADIUS_M: f64 = 0.08;
const LABEL_HEIGHT_M: f64 = 0.2;
const LINE_WIDTH_M: f64 = 0.03;
/// Lines drawn just above the floor, so that the floor does not hide them.
const LIFT_M: f64 = 0.01;

const LANDMARK: Colour = Colour([0.95, 0.75, 0.1, 1.0]);
const LABEL: Colour = Colour([1.0, 1.0, 1.0, 1.0]);
const UNCERTAINTY: Colour = Colour([1.0, 0.55, 0.0, 1.0]);
const LOST: Colour = Colour([0.9, 0.1, 0.1, 1.0]);
const PLAN: Colour = Colour([0.2, 0.8, 0.3, 1.0]);

fn marker(stamp_ns: u64, ns: &str, id: usize, kind: MarkerKind) -> Marker {
    Marker {
        stamp_ns,
        frame_id: frames::WORLD.into(),
        ns: ns.into(),
        id: i32::try_from(id).unwrap_or(i32::MAX),
        kind,
        ..Default::default()
    }
}

/// Each wall a box of its height in its own colour, each landmark a ball with its name above.
pub fn map(stamp_ns: u64, world: &World) -> MarkerArray {
    let mut out = Vec::new();
    for (k, w) in world.walls.iter().enumerate() {
        let (dx, dy) = (w.to[0] - w.from[0], w.to[1] - w.from[1]);
        let [r, g, b] = w.colour.map(|c| (c * w.reflectance.clamp(0.2, 1.0)) as f32);
        out.push(Marker {
            position: Point([(w.from[0] + w.to[0]) / 2.0, (w.from[1] + w.to[1]) / 2.0, w.height_m / 2.0]),
            orientation: Quaternion::yaw(dy.atan2(dx)),
            scale: Point([dx.hypot(dy), WALL_THICKNESS_M, w.height_m]),
            colour: Colour([r, g, b, 0.8]),
            ..marker(stamp_ns, "walls", k, MarkerKind::Cube)
        });
    }
    for (k, l) in world.landmarks.iter().enumerate() {
        let [x, y, z] = l.position_m;
        let d = 2.0 * LANDMARK_RADIUS_M;
        out.push(Marker {
            position: Point([x, y, z]),
            scale: Point([d, d, d]),
            colour: LANDMARK,
            ..marker(stamp_ns, "landmarks", k, MarkerKind::Sphere)
        });
        out.push(Marker {
            position: Point([x, y, z + l.height_m + LABEL_HEIGHT_M]),
            scale: Point([0.0, 0.0, LABEL_HEIGHT_M]),
            colour: LABEL,
            text: l.name.clone(),
            ..marker(stamp_ns, "landmark_names", k, MarkerKind::TextViewFacing)
        });
    }
    MarkerArray(out)
}

/// The polygon the robot is somewhere inside, closed; red while the UMS says it is lost.
pub fn uncertainty(stamp_ns: u64, m: &UncertaintyMap) -> MarkerArray {
    let n = (m.vertex_count as usize).min(m.vertices_m.len());
    let mut points: Vec<Point> = m.vertices_m[..n].iter().map(|v| Point([v[0], v[1], LIFT_M])).collect();
    points.extend(points.first().copied());
    MarkerArray(vec![Marker {
        scale: Point([LINE_WIDTH_M, 0.0, 0.0]),
        colour: if m.lost == 1 { LOST } else { UNCERTAINTY },
        points,
        text: format!("{:.0} cm²", m.area_m2 * 1e4),
        ..marker(stamp_ns, "uncertainty", 0, MarkerKind::LineStrip)
    }])
}

/// The subgoal's start and milestones, as a line and as balls.
pub fn plan(stamp_ns: u64, p: &PlanSketch) -> MarkerArray {
    let n = (p.place_count as usize).min(p.places_m.len() / 2);
    let points: Vec<Point> =
        (0..n).map(|k| Point([p.places_m[2 * k], p.places_m[2 * k + 1], LIFT_M])).collect();
    let line = Marker {
        scale: Point([LINE_WIDTH_M, 0.0, 0.0]),
        colour: PLAN,
        points: points.clone(),
        ..marker(stamp_ns, "plan", 0, MarkerKind::LineStrip)
    };
    let d = 2.0 * LANDMARK_RADIUS_M;
    let stops = Marker {
        scale: Point([d, d, d]),
        colour: PLAN,
        points,
        ..marker(stamp_ns, "plan", 1, MarkerKind::SphereList)
    };
    MarkerArray(vec![line, stops])
}
