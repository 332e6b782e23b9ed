//! The Rerun side of a recording (rerun 0.36.3 SDK): the camera image with the Expecter's windows
//! and landmark sightings drawn on it, a top-down world view framed on the action (walls,
//! landmarks, sonar returns, the true, dead-reckoned and estimated paths and poses, the plan, the
//! uncertainty polygon and heading wedge), one plot per quantity, state lanes and the text log,
//! on the `sim_time` and `frame` timelines. The live recorder and `harvey export` both feed it.
//!
//! The top-down view draws the world with y up: Rerun's 2D views put y down, so y is negated.

mod blueprint;
mod camera;
mod executive;
pub mod frame;
mod log;
mod vision;
mod world;
use std::path::{Path, PathBuf};

use harvey_world::World;

/// A failure of the Rerun file, naming it.
#[derive(Debug, thiserror::Error)]
pub enum RrdError {
    /// The SDK could not create the file or log to it.
    #[error("recording {file}: {cause}")]
    Log { file: PathBuf, cause: rerun::RecordingStreamError },
    /// What is logged could not be pushed to the file.
    #[error("recording {file}: {cause}")]
    Flush { file: PathBuf, cause: rerun::sink::SinkFlushError },
    /// A live viewer's address that is not a Rerun proxy URL.
    #[error("live viewer `{url}`: {what} (a viewer's address reads rerun+http://HOST:PORT/proxy)")]
    LiveUrl { url: String, what: String },
}

/// How long a flush waits for a live viewer before it goes on without it (the file is flushed
/// all the same): a viewer that is gone must not hold up the recording.
const LIVE_FLUSH_TIMEOUT: std::time::Duration = std::time::Duration::from_millis(200);
const LIVE_FINISH_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);

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

/// The colours of the drawing.
mod colour {
    use rerun::Color;
    use rerun::datatypes::Rgba32;
    pub const WALL: Color = Color(Rgba32::from_rgb(170, 170, 170));
    pub const LANDMARK: Color = Color(Rgba32::from_rgb(80, 160, 255));
    pub const FRAME: Color = Color(Rgba32::from_rgb(45, 45, 45));
    pub const TRUTH: Color = Color(Rgba32::from_rgb(60, 200, 60));
    pub const ODOMETRY: Color = Color(Rgba32::from_rgb(240, 160, 40));
    pub const ESTIMATE: Color = Color(Rgba32::from_rgb(80, 200, 240));
    pub const SONAR: Color = Color(Rgba32::from_rgb(230, 60, 60));
    pub const UNCERTAINTY: Color = Color(Rgba32::from_rgb(255, 220, 0));
    pub const LOST: Color = Color(Rgba32::from_rgb(255, 0, 0));
    pub const WINDOW: Color = Color(Rgba32::from_rgb(120, 180, 255));
    pub const SIGHTING: Color = Color(Rgba32::from_rgb(0, 255, 120));
    pub const FEATURE: Color = Color(Rgba32::from_rgb(255, 80, 200));
    pub const RESULT: Color = Color(Rgba32::from_rgb(255, 200, 0));

    /// The same colour, mostly transparent.
    pub fn faint(c: Color) -> Color {
        let [r, g, b, _] = c.to_array();
        Color::from_unmultiplied_rgba(r, g, b, 110)
    }
}

/// An open `.rrd` file.
pub struct RrdWriter {
    rec: rerun::RecordingStream,
    path: PathBuf,
    /// The latest odometry pose (x, y, heading): where sonar returns are placed.
    pose: Option<[f64; 3]>,
    /// The latest true pose: where the camera looks from.
    truth_pose: Option<[f64; 3]>,
    last_state: Option<(u32, u32, u32)>,
    /// The executive's current goal: the line the servo deviation is measured from.
    goal: Option<harvey_msgs::Pose2>,
    /// (focal, width, height) of the camera, to draw sightings' bearings on the image.
    camera: Option<(f64, f64, f64)>,
    half_fov_rad: f64,
    walls: Vec<([f64; 2], [f64; 2])>,
    landmarks: Vec<world::Mark>,
    /// Stamp of each landmark's latest Expecter window: windows not renewed are cleared.
    windows: std::collections::BTreeMap<u32, u64>,
    /// Stamp of each vision request's result on the image.
    results: std::collections::BTreeMap<u32, u64>,
    truth_trail: frame::Trail,
    odometry_trail: frame::Trail,
    estimate_trail: frame::Trail,
    /// The box the view round the robot was last drawn for, and the landmarks it labelled.
    frame: Option<frame::Bounds>,
    labelled: Vec<usize>,
    /// The current plan's places, kept in the box round the action.
    plan_places: Vec<[f64; 2]>,
    /// Milestone checks and acceptor transitions already logged; the last command and reflex
    /// logged; the UMS's last lost flag.
    plan_checks: u32,
    fsa_transitions: u32,
    /// The plan's stage and the acceptor's state last laned.
    plan_stage: Option<u32>,
    fsa_state: Option<u32>,
    last_command: Option<String>,
    last_reflex: Option<String>,
    lost: Option<bool>,
    /// The services' `rosout` lines drawn lately, so a repeated one is drawn once a while.
    repeats: log::Repeats,
    /// Also streamed to a live viewer: flushes wait for it only briefly.
    live: bool,
}

/// Paths keep a point every 5 cm, a few thousand at most.
const TRAIL_STEP_M: f64 = 0.05;
const TRAIL_CAP: usize = 4000;

impl RrdWriter {
    /// Creates the file with Harvey's blueprint, and draws the world's walls and landmarks.
    pub fn create(path: &Path, world: Option<&World>) -> Result<Self, RrdError> {
        Self::create_live(path, world, None)
    }

    /// As [`RrdWriter::create`], and with `live` (a viewer's `rerun+http://…/proxy` address) the
    /// same drawing is streamed to that viewer over gRPC while it is written to the file.
    pub fn create_live(path: &Path, world: Option<&World>, live: Option<&str>) -> Result<Self, RrdError> {
        let builder = rerun::RecordingStreamBuilder::new("harvey").with_blueprint(blueprint::harvey());
        let log_err = |cause| RrdError::Log { file: path.to_owned(), cause };
        let rec = match live {
            None => builder.save(path).map_err(log_err)?,
            Some(url) => {
                let bad = |what: String| RrdError::LiveUrl { url: url.to_owned(), what };
                let parsed: rerun::external::re_uri::RedapUri =
                    url.parse().map_err(|e| bad(format!("{e}")))?;
                let rerun::external::re_uri::RedapUri::Proxy(proxy) = parsed else {
                    return Err(bad("not a proxy endpoint".into()));
                };
                let file = rerun::sink::FileSink::new(path)
                    .map_err(|e| log_err(rerun::RecordingStreamError::from(e)))?;
                builder.set_sinks((rerun::sink::GrpcSink::new(proxy), file)).map_err(log_err)?
            }
        };
        let camera =
            world.map(|w| (w.camera.focal_px, f64::from(w.camera.width_px), f64::from(w.camera.height_px)));
        let half_fov_rad = camera.map_or(30f64.to_radians(), |(f, w, _)| (w / 2.0 / f).atan());
        let mut w = Self {
            rec,
            path: path.to_owned(),
            pose: None,
            truth_pose: None,
            last_state: None,
            goal: None,
            camera,
            half_fov_rad,
            walls: world.map(|w| w.walls.iter().map(|w| (w.from, w.to)).collect()).unwrap_or_default(),
            landmarks: world.map(world::marks).unwrap_or_default(),
            windows: Default::default(),
            results: Default::default(),
            truth_trail: frame::Trail::new(TRAIL_STEP_M, TRAIL_CAP),
            odometry_trail: frame::Trail::new(TRAIL_STEP_M, TRAIL_CAP),
            estimate_trail: frame::Trail::new(TRAIL_STEP_M, TRAIL_CAP),
            frame: None,
            labelled: Vec::new(),
            plan_places: Vec::new(),
            plan_checks: 0,
            fsa_transitions: 0,
            plan_stage: None,
            fsa_state: None,
            last_command: None,
            last_reflex: None,
            lost: None,
            repeats: log::Repeats::default(),
            live: live.is_some(),
        };
        w.name_the_plots()?;
        w.draw_world()?;
        Ok(w)
    }

    fn err(&self, cause: rerun::RecordingStreamError) -> RrdError {
        RrdError::Log { file: self.path.clone(), cause }
    }

    fn at(&self, stamp_ns: u64) {
        self.rec.set_duration_secs("sim_time", stamp_ns as f64 / 1e9);
    }

    /// Each plotted series' name in its panel's legend.
    fn name_the_plots(&self) -> Result<(), RrdError> {
        for (path, name) in [
            ("plots/uncertainty/area_m2", "area of the uncertainty polygon"),
            ("plots/heading/wedge_deg", "heading wedge width"),
            ("plots/deviation/true_m", "true (from sim/truth)"),
            ("plots/deviation/estimated_m", "as the servo estimated it"),
            ("plots/servo/heading_error_deg", "heading error"),
            ("plots/servo/correction_deg", "turn commanded"),
            ("plots/speed/linear_mps", "velocity command: speed"),
            ("plots/turning/angular_degps", "velocity command: turn rate"),
            ("plots/vision/light_px", "phototropic: light blob size"),
            ("plots/latency/loop_ms", "every party's turn for one tick"),
        ] {
            self.rec
                .log_static(path, &rerun::SeriesLines::new().with_names([name]))
                .map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    /// Deterministic mode: the wall time every service together took for the tick at `stamp_ns`.
    pub fn loop_latency(&mut self, stamp_ns: u64, wall_ms: f64) -> Result<(), RrdError> {
        self.at(stamp_ns);
        self.rec.log("plots/latency/loop_ms", &rerun::Scalars::single(wall_ms)).map_err(|e| self.err(e))
    }

    /// Pushes what is logged so far to the file.
    pub fn flush(&self) -> Result<(), RrdError> {
        let flushed = if self.live {
            self.rec.flush_with_timeout(LIVE_FLUSH_TIMEOUT)
        } else {
            self.rec.flush_blocking()
        };
        match flushed {
            // A viewer that does not keep up, or has gone, is left behind: the file sink has
            // taken what was drawn, and the run goes on.
            Err(e) if self.live => {
                tracing::debug!("the live viewer: {e}");
                Ok(())
            }
            other => other.map_err(|cause| RrdError::Flush { file: self.path.clone(), cause }),
        }
    }

    /// Flushes and closes the file (the footer is written when the stream drops).
    pub fn finish(self) -> Result<(), RrdError> {
        self.flush()?;
        if self.live {
            // The end of the run: a live viewer gets a few seconds to take the rest.
            if let Err(e) = self.rec.flush_with_timeout(LIVE_FINISH_TIMEOUT) {
                tracing::warn!("the live viewer did not take the end of the run: {e}");
            }
        }
        drop(self.rec);
        Ok(())
    }
}
