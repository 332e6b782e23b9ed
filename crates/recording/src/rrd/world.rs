//! The top-down world view: the map (walls, landmarks) for the whole-world tab; for the view round
//! the robot the walls clipped to the box round the action and labels only on the landmarks the
//! camera has in view or the Expecter has a window on; the true, dead-reckoned and estimated
//! paths as lines; the robot's true and odometry poses; sonar returns; the uncertainty polygon
//! true to scale (cut at the box in the view round the robot, whole in the whole world's) and,
//! while it is small, enlarged 2, 5 or 10 times about its centre; its heading wedge.

use harvey_msgs::{Odometry, SonarRing, TruePose, UncertaintyMap};
use harvey_world::World;

use super::frame::{Bounds, clip, in_view};
use super::{RrdError, RrdWriter, colour, pose_arrow, ray, up};

/// The last metres of the true path the view round the robot keeps in its box.
const RECENT_PATH_M: f64 = 8.0;
/// Margin round the action and the least side of the box (metres).
const FRAME_MARGIN_M: f64 = 1.0;
const FRAME_MIN_SIDE_M: f64 = 4.0;
/// The box is redrawn once a side has moved this far.
const FRAME_STEP_M: f64 = 0.25;
/// A landmark farther than this is not labelled as in view.
const VIEW_RANGE_M: f64 = 12.0;
/// The uncertainty polygon's enlarged copy (cm-sized polygons, m-sized halls): drawn about this
/// wide, enlarged by at most ten, and not at all once the polygon itself is that wide.
const ENLARGED_WIDTH_M: f64 = 0.6;
const ENLARGE_MAX: f64 = 10.0;

/// How much to enlarge a polygon `width_m` wide: 2, 5 or 10 times, or 1 (not at all).
pub(super) fn enlargement(width_m: f64) -> f64 {
    let wanted = ENLARGED_WIDTH_M / width_m.max(1e-9);
    [ENLARGE_MAX, 5.0, 2.0].into_iter().find(|&k| k <= wanted).unwrap_or(1.0)
}

/// A landmark as the view draws it.
#[derive(Debug, Clone)]
pub(super) struct Mark {
    pub name: String,
    pub label: String,
    pub at: [f64; 2],
}

pub(super) fn marks(world: &World) -> Vec<Mark> {
    let label = |l: &harvey_world::Landmark| format!("{} ({:?})", l.name, l.class);
    world
        .landmarks
        .iter()
        .map(|l| Mark { name: l.name.clone(), label: label(l), at: [l.position_m[0], l.position_m[1]] })
        .collect()
}

fn strip(points: &[[f64; 2]]) -> Vec<[f32; 2]> {
    points.iter().map(|p| up(*p)).collect()
}

impl RrdWriter {
    pub(super) fn draw_world(&mut self) -> Result<(), RrdError> {
        let walls: Vec<Vec<[f32; 2]>> = self.walls.iter().map(|(a, b)| vec![up(*a), up(*b)]).collect();
        let walls = rerun::LineStrips2D::new(walls).with_colors([colour::WALL]);
        self.rec.log_static("world/map/walls", &walls).map_err(|e| self.err(e))?;
        let marks = rerun::Points2D::new(self.landmarks.iter().map(|m| up(m.at)))
            .with_radii([0.08])
            .with_colors([colour::LANDMARK]);
        self.rec.log_static("world/map/landmarks", &marks).map_err(|e| self.err(e))
    }

    pub fn truth(&mut self, m: &TruePose) -> Result<(), RrdError> {
        self.at(m.header.stamp_ns);
        let p = m.world_from_robot;
        self.truth_pose = Some([p.x_m, p.y_m, p.heading_rad]);
        self.rec.log("world/robot/truth", &pose_arrow(&p, colour::TRUTH)).map_err(|e| self.err(e))?;
        if self.truth_trail.push([p.x_m, p.y_m]) {
            self.path_line("world/paths/truth", &self.truth_trail.points, colour::TRUTH)?;
        }
        self.frame_the_action()?;
        // Servo deviation: how far the true robot is off the line it is driving, the line
        // through the executive's current goal along the goal's heading (positive: left of it).
        let Some(g) = self.goal else { return Ok(()) };
        let off = -(p.x_m - g.x_m) * g.heading_rad.sin() + (p.y_m - g.y_m) * g.heading_rad.cos();
        self.rec.log("plots/deviation/true_m", &rerun::Scalars::single(off)).map_err(|e| self.err(e))
    }

    pub fn odometry(&mut self, m: &Odometry) -> Result<(), RrdError> {
        self.at(m.header.stamp_ns);
        let p = m.world_from_robot;
        self.pose = Some([p.x_m, p.y_m, p.heading_rad]);
        self.rec.log("world/robot/odometry", &pose_arrow(&p, colour::ODOMETRY)).map_err(|e| self.err(e))?;
        if self.odometry_trail.push([p.x_m, p.y_m]) {
            self.path_line("world/paths/odometry", &self.odometry_trail.points, colour::ODOMETRY)?;
        }
        Ok(())
    }

    /// The executive's belief of where it is, as a path.
    pub(super) fn estimate(&mut self, p: &harvey_msgs::Pose2) -> Result<(), RrdError> {
        if !self.estimate_trail.push([p.x_m, p.y_m]) {
            return Ok(());
        }
        self.path_line("world/paths/estimated", &self.estimate_trail.points, colour::ESTIMATE)
    }

    /// A trail's points drawn as one line.
    fn path_line(&self, path: &str, points: &[[f64; 2]], tint: rerun::Color) -> Result<(), RrdError> {
        let line = rerun::LineStrips2D::new([strip(points)]).with_colors([tint]);
        self.rec.log(path, &line).map_err(|e| self.err(e))
    }

    /// Redraws the view round the robot when the box round the action has moved or the set of
    /// landmarks worth a label has changed.
    fn frame_the_action(&mut self) -> Result<(), RrdError> {
        let Some(pose) = self.truth_pose else { return Ok(()) };
        let mut action = Bounds::around([pose[0], pose[1]]);
        for p in self.truth_trail.recent(RECENT_PATH_M) {
            action.include(*p);
        }
        if let Some(g) = self.goal {
            action.include([g.x_m, g.y_m]);
        }
        for p in &self.plan_places {
            action.include(*p);
        }
        let frame = action.framed(FRAME_MARGIN_M, FRAME_MIN_SIDE_M);
        let labelled: Vec<usize> = (0..self.landmarks.len())
            .filter(|&i| {
                let at = self.landmarks[i].at;
                frame.contains(at)
                    && (in_view(pose, at, self.half_fov_rad, VIEW_RANGE_M)
                        || self.windows.contains_key(&(i as u32)))
            })
            .collect();
        let unchanged = self.frame.is_some_and(|f| f.moved_from(&frame) < FRAME_STEP_M);
        if unchanged && labelled == self.labelled {
            return Ok(());
        }
        if !unchanged {
            self.frame = Some(frame);
        }
        self.labelled = labelled;
        let frame = self.frame.unwrap_or(frame);
        let walls: Vec<Vec<[f32; 2]>> = self
            .walls
            .iter()
            .filter_map(|(a, b)| clip(*a, *b, &frame))
            .map(|(a, b)| vec![up(a), up(b)])
            .collect();
        let walls = rerun::LineStrips2D::new(walls).with_colors([colour::WALL]).with_radii([0.025]);
        self.rec.log("world/near/walls", &walls).map_err(|e| self.err(e))?;
        let inside: Vec<usize> =
            (0..self.landmarks.len()).filter(|&i| frame.contains(self.landmarks[i].at)).collect();
        let labels = inside
            .iter()
            .map(|i| if self.labelled.contains(i) { self.landmarks[*i].label.as_str() } else { "" });
        let marks = rerun::Points2D::new(inside.iter().map(|i| up(self.landmarks[*i].at)))
            .with_labels(labels)
            .with_radii([0.07])
            .with_colors([colour::LANDMARK]);
        self.rec.log("world/near/landmarks", &marks).map_err(|e| self.err(e))?;
        let [x0, y0] = up(frame.min);
        let [x1, y1] = up(frame.max);
        let border = rerun::Boxes2D::from_mins_and_sizes([(x0, y1)], [(x1 - x0, y0 - y1)])
            .with_colors([colour::FRAME]);
        self.rec.log("world/near/frame", &border).map_err(|e| self.err(e))
    }

    /// Sonar returns, placed in the world from the latest odometry pose: all of them in the
    /// whole-world tab, those inside the box round the action in the view round the robot.
    pub fn sonar(&mut self, m: &SonarRing) -> Result<(), RrdError> {
        let Some([x, y, th]) = self.pose else { return Ok(()) };
        self.at(m.header.stamp_ns);
        let pts: Vec<[f64; 2]> = (0..m.range_m.len())
            .filter(|i| m.valid_mask & (1 << i) != 0)
            .map(|i| {
                let a = th + f64::from(m.bearing_rad[i]);
                let r = f64::from(m.range_m[i]);
                [x + r * a.cos(), y + r * a.sin()]
            })
            .collect();
        let near: Vec<[f64; 2]> =
            pts.iter().copied().filter(|p| self.frame.is_none_or(|f| f.contains(*p))).collect();
        for (path, pts) in [("world/map/sonar", pts), ("world/near/sonar", near)] {
            let returns = rerun::Points2D::new(strip(&pts)).with_radii([0.04]).with_colors([colour::SONAR]);
            self.rec.log(path, &returns).map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    /// The uncertainty polygon (and its enlarged copy), the heading wedge (two rays from the
    /// centre), their plots, and the UMS's localised or lost state.
    pub fn map(&mut self, m: &UncertaintyMap) -> Result<(), RrdError> {
        self.at(m.header.stamp_ns);
        let n = (m.vertex_count as usize).min(m.vertices_m.len());
        let c = m.centre;
        let lost = m.lost == 1;
        let tint = if lost { colour::LOST } else { colour::UNCERTAINTY };
        let ring = |scale: f64| -> Vec<[f32; 2]> {
            let mut ring: Vec<[f32; 2]> = m.vertices_m[..n]
                .iter()
                .map(|v| up([c.x_m + scale * (v[0] - c.x_m), c.y_m + scale * (v[1] - c.y_m)]))
                .collect();
            ring.extend(ring.first().copied());
            ring
        };
        let polygon = rerun::LineStrips2D::new([ring(1.0)]).with_colors([tint]);
        self.rec.log("world/map/uncertainty", &polygon).map_err(|e| self.err(e))?;
        // Round the robot, a lost robot's polygon (hundreds of metres wide) is cut at the box
        // instead of taking the view over.
        let corners = &m.vertices_m[..n];
        let edges: Vec<Vec<[f32; 2]>> = match self.frame {
            None => vec![ring(1.0)],
            Some(f) => (0..n)
                .filter_map(|k| clip(corners[k], corners[(k + 1) % n], &f))
                .map(|(a, b)| vec![up(a), up(b)])
                .collect(),
        };
        let near = rerun::LineStrips2D::new(edges).with_colors([tint]);
        self.rec.log("world/near/uncertainty", &near).map_err(|e| self.err(e))?;
        let width = m.vertices_m[..n]
            .iter()
            .flat_map(|a| m.vertices_m[..n].iter().map(move |b| (a[0] - b[0]).hypot(a[1] - b[1])))
            .fold(0.0, f64::max);
        let k = enlargement(width);
        if k > 1.0 {
            let enlarged = rerun::LineStrips2D::new([ring(k)])
                .with_colors([colour::faint(tint)])
                .with_labels([format!("uncertainty x{k:.0}: {:.0} cm²", m.area_m2 * 1e4)]);
            self.rec.log("world/robot/uncertainty_enlarged", &enlarged).map_err(|e| self.err(e))?;
        } else {
            self.rec
                .log("world/robot/uncertainty_enlarged", &rerun::Clear::flat())
                .map_err(|e| self.err(e))?;
        }
        let wedge = rerun::Arrows2D::from_vectors([
            ray(c.heading_rad - m.heading_cw_rad, 1.0),
            ray(c.heading_rad + m.heading_ccw_rad, 1.0),
        ])
        .with_origins([up([c.x_m, c.y_m]), up([c.x_m, c.y_m])])
        .with_colors([tint]);
        self.rec.log("world/robot/wedge", &wedge).map_err(|e| self.err(e))?;
        self.rec
            .log("plots/uncertainty/area_m2", &rerun::Scalars::single(m.area_m2))
            .map_err(|e| self.err(e))?;
        let wedge_deg = (m.heading_cw_rad + m.heading_ccw_rad).to_degrees();
        self.rec
            .log("plots/heading/wedge_deg", &rerun::Scalars::single(wedge_deg))
            .map_err(|e| self.err(e))?;
        self.clear_stale_overlays(m.header.stamp_ns)?;
        self.ums_state(lost)
    }
}

#[cfg(test)]
mod tests {
    use super::enlargement;

    #[test]
    fn a_small_polygon_is_enlarged_to_be_seen_and_a_large_one_is_not() {
        assert_eq!(enlargement(0.02), 10.0, "2 cm: ten times");
        assert_eq!(enlargement(0.1), 5.0, "10 cm: five times, 50 cm drawn");
        assert_eq!(enlargement(0.25), 2.0);
        assert_eq!(enlargement(0.45), 1.0, "already about as wide as the enlarged copy");
        assert_eq!(enlargement(3.0), 1.0);
    }
}
