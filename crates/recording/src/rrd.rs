//! The Rerun side of a recording (rerun 0.36.3 SDK): the camera image with the Expecter's windows
//! and landmark sightings drawn on it, a top-down world view (walls, landmarks, sonar returns,
//! true and estimated pose, the uncertainty polygon and heading wedge), plots, and the text log,
//! on the `sim_time` and `frame` timelines. The live recorder and `harvey export` both feed it.
//!
//! The top-down view draws the world with y up: Rerun's 2D views put y down, so y is negated.

mod executive;
mod vision;
use std::path::{Path, PathBuf};

use harvey_msgs::{
    Detections, Expectation, FrameHeader, LandmarkSighting, MissionStatus, MotionCommand, Odometry,
    SonarRing, TruePose, UncertaintyMap,
};
use harvey_world::World;
use rerun::blueprint::{Blueprint, Horizontal, Spatial2DView, TextLogView, TimeSeriesView, Vertical};

/// A failure of the Rerun file, naming it.
#[derive(Debug, thiserror::Error)]
pub enum RrdError {
    /// The SDK could not create the file or log to it.
    #[error("recording {file}: {cause}")]
    Log { file: PathBuf, cause: rerun::RecordingStreamError },
    /// What is logged could not be pushed to the file.
    #[error("recording {file}: {cause}")]
    Flush { file: PathBuf, cause: rerun::sink::SinkFlushError },
}

fn up(p: [f64; 2]) -> [f32; 2] {
    [p[0] as f32, -p[1] as f32]
}

/// A vector of `length_m` along `heading_rad`, in the y-up drawing.
fn ray(heading_rad: f64, length_m: f64) -> [f32; 2] {
    up([length_m * heading_rad.cos(), length_m * heading_rad.sin()])
}

/// A pose as an arrow from its position along its heading.
fn pose_arrow(p: &harvey_msgs::Pose2, colour: rerun::Color) -> rerun::Arrows2D {
    rerun::Arrows2D::from_vectors([ray(p.heading_rad, 0.5)])
        .with_origins([up([p.x_m, p.y_m])])
        .with_colors([colour])
}

/// An open `.rrd` file.
pub struct RrdWriter {
    rec: rerun::RecordingStream,
    path: PathBuf,
    pose: Option<[f64; 3]>,
    last_state: Option<(u32, u32, u32)>,
    /// The executive's current goal: the line the servo deviation is measured from.
    goal: Option<harvey_msgs::Pose2>,
    /// (focal, width, height) of the camera, to draw sightings' bearings on the image.
    camera: Option<(f64, f64, f64)>,
    /// Stamp of each landmark's latest Expecter window: windows not renewed are cleared.
    windows: std::collections::BTreeMap<u32, u64>,
    /// Milestone checks already logged.
    plan_checks: u32,
    /// Acceptor transitions already logged.
    fsa_transitions: u32,
}

/// A window not renewed for this long (message time) is taken off the image.
const WINDOW_LIFETIME_NS: u64 = 300_000_000;

impl RrdWriter {
    /// Creates the file with Harvey's blueprint, and draws the world's walls and landmarks.
    pub fn create(path: &Path, world: Option<&World>) -> Result<Self, RrdError> {
        let blueprint = Blueprint::new(Horizontal::new([
            Vertical::new([
                Spatial2DView::new("camera").with_origin("/camera").into(),
                TextLogView::new("log").with_origin("/log").into(),
            ])
            .into(),
            Vertical::new([
                Spatial2DView::new("world (top-down, y up)").with_origin("/world").into(),
                TimeSeriesView::new("plots").with_origin("/plots").into(),
            ])
            .into(),
        ]));
        let rec = rerun::RecordingStreamBuilder::new("harvey")
            .with_blueprint(blueprint)
            .save(path)
            .map_err(|cause| RrdError::Log { file: path.to_owned(), cause })?;
        let camera =
            world.map(|w| (w.camera.focal_px, f64::from(w.camera.width_px), f64::from(w.camera.height_px)));
        let mut w = Self {
            rec,
            path: path.to_owned(),
            pose: None,
            last_state: None,
            goal: None,
            camera,
            windows: Default::default(),
            plan_checks: 0,
            fsa_transitions: 0,
        };
        if let Some(world) = world {
            w.draw_world(world)?;
        }
        Ok(w)
    }

    fn err(&self, cause: rerun::RecordingStreamError) -> RrdError {
        RrdError::Log { file: self.path.clone(), cause }
    }

    fn at(&self, stamp_ns: u64) {
        self.rec.set_duration_secs("sim_time", stamp_ns as f64 / 1e9);
    }

    fn draw_world(&mut self, world: &World) -> Result<(), RrdError> {
        let walls: Vec<Vec<[f32; 2]>> = world.walls.iter().map(|w| vec![up(w.from), up(w.to)]).collect();
        let grey = rerun::Color::from_rgb(170, 170, 170);
        self.rec
            .log_static("world/walls", &rerun::LineStrips2D::new(walls).with_colors([grey]))
            .map_err(|e| self.err(e))?;
        let marks: Vec<[f32; 2]> =
            world.landmarks.iter().map(|l| up([l.position_m[0], l.position_m[1]])).collect();
        let names: Vec<String> =
            world.landmarks.iter().map(|l| format!("{} ({:?})", l.name, l.class)).collect();
        let landmarks = rerun::Points2D::new(marks)
            .with_labels(names)
            .with_radii([0.08])
            .with_colors([rerun::Color::from_rgb(80, 160, 255)]);
        self.rec.log_static("world/landmarks", &landmarks).map_err(|e| self.err(e))
    }

    pub fn truth(&mut self, m: &TruePose) -> Result<(), RrdError> {
        self.at(m.header.stamp_ns);
        let arrow = pose_arrow(&m.world_from_robot, rerun::Color::from_rgb(60, 200, 60));
        self.rec.log("world/truth", &arrow).map_err(|e| self.err(e))?;
        // Servo deviation: how far the true robot is off the line it is driving, the line
        // through the executive's current goal along the goal's heading (positive: left of it).
        let Some(g) = self.goal else { return Ok(()) };
        let p = m.world_from_robot;
        let off = -(p.x_m - g.x_m) * g.heading_rad.sin() + (p.y_m - g.y_m) * g.heading_rad.cos();
        self.rec.log("plots/servo_deviation_m", &rerun::Scalars::single(off)).map_err(|e| self.err(e))
    }

    /// Deterministic mode: the wall time every service together took for the tick at `stamp_ns`.
    pub fn loop_latency(&mut self, stamp_ns: u64, wall_ms: f64) -> Result<(), RrdError> {
        self.at(stamp_ns);
        self.rec.log("plots/loop_latency_ms", &rerun::Scalars::single(wall_ms)).map_err(|e| self.err(e))
    }

    pub fn odometry(&mut self, m: &Odometry) -> Result<(), RrdError> {
        self.at(m.header.stamp_ns);
        let p = m.world_from_robot;
        self.pose = Some([p.x_m, p.y_m, p.heading_rad]);
        let arrow = pose_arrow(&p, rerun::Color::from_rgb(240, 160, 40));
        self.rec.log("world/odometry", &arrow).map_err(|e| self.err(e))
    }

    /// Sonar returns, placed in the world from the latest odometry pose.
    pub fn sonar(&mut self, m: &SonarRing) -> Result<(), RrdError> {
        let Some([x, y, th]) = self.pose else { return Ok(()) };
        self.at(m.header.stamp_ns);
        let pts: Vec<[f32; 2]> = (0..m.range_m.len())
            .filter(|i| m.valid_mask & (1 << i) != 0)
            .map(|i| {
                let a = th + f64::from(m.bearing_rad[i]);
                let r = f64::from(m.range_m[i]);
                up([x + r * a.cos(), y + r * a.sin()])
            })
            .collect();
        self.rec
            .log(
                "world/sonar",
                &rerun::Points2D::new(pts)
                    .with_radii([0.04])
                    .with_colors([rerun::Color::from_rgb(230, 60, 60)]),
            )
            .map_err(|e| self.err(e))
    }

    /// The uncertainty polygon, the heading wedge (two rays from the centre) and the area plot.
    pub fn map(&mut self, m: &UncertaintyMap) -> Result<(), RrdError> {
        self.at(m.header.stamp_ns);
        let n = m.vertex_count as usize;
        let mut ring: Vec<[f32; 2]> = m.vertices_m[..n].iter().map(|v| up(*v)).collect();
        if let Some(first) = ring.first().copied() {
            ring.push(first);
        }
        let colour =
            if m.lost == 1 { rerun::Color::from_rgb(255, 0, 0) } else { rerun::Color::from_rgb(255, 220, 0) };
        self.rec
            .log("world/uncertainty/polygon", &rerun::LineStrips2D::new([ring]).with_colors([colour]))
            .map_err(|e| self.err(e))?;
        let c = m.centre;
        let wedge = rerun::Arrows2D::from_vectors([
            ray(c.heading_rad - m.heading_cw_rad, 1.0),
            ray(c.heading_rad + m.heading_ccw_rad, 1.0),
        ])
        .with_origins([up([c.x_m, c.y_m]), up([c.x_m, c.y_m])])
        .with_colors([colour]);
        self.rec.log("world/uncertainty/wedge", &wedge).map_err(|e| self.err(e))?;
        self.rec
            .log("plots/uncertainty_area_m2", &rerun::Scalars::single(m.area_m2))
            .map_err(|e| self.err(e))?;
        let stale: Vec<u32> = self
            .windows
            .iter()
            .filter(|(_, t)| **t + WINDOW_LIFETIME_NS < m.header.stamp_ns)
            .map(|(i, _)| *i)
            .collect();
        for i in stale {
            self.windows.remove(&i);
            self.rec
                .log(format!("camera/image/expectations/{i}"), &rerun::Clear::flat())
                .map_err(|e| self.err(e))?;
        }
        let wedge_deg = (m.heading_cw_rad + m.heading_ccw_rad).to_degrees();
        self.rec.log("plots/heading_wedge_deg", &rerun::Scalars::single(wedge_deg)).map_err(|e| self.err(e))
    }

    pub fn frame(&mut self, h: &FrameHeader, pixels: &[u8]) -> Result<(), RrdError> {
        self.at(h.stamp_ns);
        self.rec.set_time_sequence("frame", h.seq as i64);
        let size = [h.width_px, h.height_px];
        let image = match h.encoding() {
            Some(harvey_msgs::Encoding::Rgb8) => rerun::Image::from_rgb24(pixels.to_vec(), size),
            _ => rerun::Image::from_l8(pixels.to_vec(), size),
        };
        self.rec.log("camera/image", &image).map_err(|e| self.err(e))
    }

    pub fn expectation(&mut self, e: &Expectation) -> Result<(), RrdError> {
        self.at(e.header.stamp_ns);
        self.windows.insert(e.landmark_index, e.header.stamp_ns);
        let [u0, v0, u1, v1] = e.window_px;
        let boxes = rerun::Boxes2D::from_mins_and_sizes([(u0, v0)], [(u1 - u0, v1 - v0)])
            .with_labels([format!("landmark {}", e.landmark_index)]);
        self.rec
            .log(format!("camera/image/expectations/{}", e.landmark_index), &boxes)
            .map_err(|e| self.err(e))
    }

    /// A recognised landmark: a vertical line at its bearing's column (for class I and II).
    pub fn sighting(&mut self, s: &LandmarkSighting) -> Result<(), RrdError> {
        let Some((f, w, h)) = self.camera else { return Ok(()) };
        self.at(s.header.stamp_ns);
        if s.kind == 1 || s.kind == 2 {
            let u = (w / 2.0 - f * s.a.tan()) as f32;
            let line = rerun::LineStrips2D::new([vec![[u, 0.0], [u, h as f32]]])
                .with_colors([rerun::Color::from_rgb(0, 255, 120)]);
            self.rec
                .log(format!("camera/image/sightings/{}", s.landmark_index), &line)
                .map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    /// A vision worker's features, as points on the image.
    pub fn detections(&mut self, d: &Detections) -> Result<(), RrdError> {
        self.at(d.header.stamp_ns);
        let n = (d.count as usize).min(d.features.len());
        let pts: Vec<[f32; 2]> = d.features[..n].iter().map(|f| [f.x_px, f.y_px]).collect();
        self.rec
            .log(
                "camera/image/features",
                &rerun::Points2D::new(pts)
                    .with_radii([2.0])
                    .with_colors([rerun::Color::from_rgb(255, 80, 200)]),
            )
            .map_err(|e| self.err(e))
    }

    pub fn command(&mut self, c: &MotionCommand) -> Result<(), RrdError> {
        self.at(c.header.stamp_ns);
        let text = format!(
            "command {}: kind {} distance {:.3} m angle {:.1} deg{}",
            c.command_id,
            c.kind,
            c.distance_m,
            c.angle_rad.to_degrees(),
            if c.urgent != 0 { " (URGENT)" } else { "" }
        );
        self.rec
            .log("log", &rerun::TextLog::new(text).with_level(rerun::TextLogLevel::INFO))
            .map_err(|e| self.err(e))
    }

    /// The executive's status, logged when its state or step changes.
    pub fn status(&mut self, s: &MissionStatus) -> Result<(), RrdError> {
        self.goal = Some(s.goal);
        if self.last_state == Some((s.state, s.step, s.servo)) {
            return Ok(());
        }
        self.last_state = Some((s.state, s.step, s.servo));
        self.at(s.header.stamp_ns);
        let servo = harvey_msgs::ServoLevel::from_raw(s.servo).map_or("?", |l| match l {
            harvey_msgs::ServoLevel::None => "none",
            harvey_msgs::ServoLevel::Action => "action-level",
            harvey_msgs::ServoLevel::Plan => "plan-level",
            harvey_msgs::ServoLevel::Goal => "goal-level",
        });
        let text = format!("mission state {} step {}/{}, servoing: {servo}", s.state, s.step, s.step_count);
        self.rec
            .log("log", &rerun::TextLog::new(text).with_level(rerun::TextLogLevel::INFO))
            .map_err(|e| self.err(e))
    }

    /// Pushes what is logged so far to the file.
    pub fn flush(&self) -> Result<(), RrdError> {
        self.rec.flush_blocking().map_err(|cause| RrdError::Flush { file: self.path.clone(), cause })
    }

    /// Flushes and closes the file (the footer is written when the stream drops).
    pub fn finish(self) -> Result<(), RrdError> {
        self.flush()?;
        drop(self.rec);
        Ok(())
    }
}
