//! What the odometry tests on rendered stereo pairs share: a world with a condition file's
//! `[camera]` table merged in, a stereo camera on one misaligned mount with the camera's
//! imperfections, the odometry's settings (003's constraints), and a run over a course of stops
//! held to the truth step by step.

use harvey_geometry::Rng;
use harvey_msgs::Encoding;
use harvey_render::{Effects, Renderer, mount_error};
use harvey_vision::Gray;
use harvey_vision::odometry::{Motion, OdometryError, OdometryParams, Prior, Solver, VisualOdometry};
use harvey_world::{Pose2, World};

#[path = "odometry_params.rs"]
mod odometry_params;

pub const W: u32 = 640;
pub const H: u32 = 480;

/// `worlds/NAME.toml` with a condition file's `[camera]` table merged in, as `harvey sweep`
/// merges it.
pub fn world(name: &str, condition: &str) -> World {
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/../../worlds/{name}.toml")).expect("reads");
    let mut world: toml::Table = toml::from_str(&text).expect("parses");
    if condition != "nominal" {
        let path = format!("{root}/../../conditions/{condition}.toml");
        let over: toml::Table =
            toml::from_str(&std::fs::read_to_string(path).expect("reads")).expect("parses");
        let camera = world.get_mut("camera").and_then(|c| c.as_table_mut()).expect("a camera table");
        for (k, v) in over["camera"].as_table().expect("a camera table") {
            camera.insert(k.clone(), v.clone());
        }
    }
    harvey_world::load_str(&toml::to_string(&world).expect("prints"), name).expect("loads")
}

/// The world's stereo rig's baseline (m).
pub fn baseline(w: &World) -> f64 {
    w.camera.stereo_baseline_m.unwrap_or(0.25)
}

/// Two renderers on one misaligned mount, the left camera `baseline / 2` left of the robot.
pub struct StereoCamera {
    renderer: Renderer,
    effects: Effects,
    frames: u64,
}

impl StereoCamera {
    pub fn new(w: &World, seed: u64) -> Self {
        let (yaw, pitch) = mount_error(&w.camera, seed);
        let renderer = Renderer::new(w, W, H, Encoding::Mono8).misaligned(yaw, pitch);
        Self { renderer, effects: Effects::from_camera(&w.camera, seed), frames: 0 }
    }

    /// The pair seen from `pose` at `stamp_s` of the run.
    pub fn pair(&mut self, w: &World, pose: Pose2, stamp_s: f64) -> (Vec<u8>, Vec<u8>) {
        let mut shot = |side: f64| {
            let mut px = vec![0u8; self.renderer.frame_bytes()];
            self.renderer.render(w, pose.sideways(side * baseline(w) / 2.0), &mut px).expect("renders");
            self.effects.apply_at(W as usize, H as usize, 1, self.frames, (stamp_s * 1e9) as u64, &mut px);
            self.frames += 1;
            px
        };
        (shot(1.0), shot(-1.0))
    }
}

/// The odometry's settings for this camera and rig.
pub fn params(w: &World) -> OdometryParams {
    odometry_params::params(w, W, H, baseline(w), Solver::MatchThenSolve)
}

pub fn gray(px: &[u8]) -> Gray<'_> {
    Gray::new(px, W as usize, H as usize, W as usize).expect("a frame")
}

#[derive(Debug, Default)]
pub struct Figures {
    pub steps: usize,
    /// Stops without a motion solution (the prediction kept for them).
    pub failed: usize,
    /// The worst of the solved steps.
    pub worst_step_m: f64,
    pub worst_heading_rad: f64,
    /// The prediction's worst step, for comparison.
    pub worst_predicted_m: f64,
    pub worst_predicted_rad: f64,
    /// The fewest features a solution rested on.
    pub fewest_used: usize,
    pub final_error_m: f64,
    pub travelled_m: f64,
}

impl std::fmt::Display for Figures {
    fn fmt(&self, out: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            out,
            "{} steps over {:.2} m, {} unsolved, worst step {:.3} m {:.2} deg (predicted {:.3} m {:.2} deg), \
             fewest features {}, position model {:.3} m off at the end",
            self.steps,
            self.travelled_m,
            self.failed,
            self.worst_step_m,
            self.worst_heading_rad.to_degrees(),
            self.worst_predicted_m,
            self.worst_predicted_rad.to_degrees(),
            self.fewest_used,
            self.final_error_m
        )
    }
}

/// Runs the odometry over the course `poses` in `w`: each step's prediction is the true motion
/// with odometry's errors (3 % of the distance, a degree of heading), its margins a little wider.
pub fn run(w: &World, poses: &[Pose2], seed: u64, solver: Solver) -> Figures {
    let w = w.clone();
    let mut camera = StereoCamera::new(&w, seed);
    let mut vo = VisualOdometry::new(OdometryParams { solver, ..params(&w) });
    let mut rng = Rng::new(seed ^ 0x5eed);
    let (l, r) = camera.pair(&w, poses[0], 0.0);
    let started = vo.start(&gray(&l), &gray(&r)).expect("starts");
    assert!(started >= 8, "{started} features at the first stop");
    let (mut model, mut f) = (poses[0], Figures { fewest_used: usize::MAX, ..Figures::default() });
    for (k, pair) in poses.windows(2).enumerate() {
        let truth = pair[0].relative(&pair[1]);
        let d = truth.x_m.hypot(truth.y_m);
        let predicted = Motion {
            x_m: truth.x_m * (1.0 + rng.normal(0.0, 0.03)),
            y_m: truth.y_m + rng.normal(0.0, 0.03 * d),
            heading_rad: truth.heading_rad + rng.normal(0.0, 1f64.to_radians()),
        };
        let prior = Prior { motion: predicted, sd: [0.05 * d + 0.01, 0.05 * d + 0.01, 2f64.to_radians()] };
        let (l, r) = camera.pair(&w, pair[1], 3.0 * (k + 1) as f64);
        // A stop without a solution, or with one past the reasonableness limit, keeps the
        // prediction (the executive would stop and look).
        let (step, solved) = match vo.step(&gray(&l), &gray(&r), &prior) {
            Ok(report) => {
                f.fewest_used = f.fewest_used.min(report.solution.used);
                (report.solution.motion, true)
            }
            Err(OdometryError::NoSolution { .. } | OdometryError::Implausible { .. }) => {
                f.failed += 1;
                (predicted, false)
            }
            Err(e) => panic!("{e}"),
        };
        let guess = Pose2 { x_m: predicted.x_m, y_m: predicted.y_m, heading_rad: predicted.heading_rad };
        f.worst_predicted_m = f.worst_predicted_m.max(guess.distance(&truth));
        f.worst_predicted_rad = f.worst_predicted_rad.max((predicted.heading_rad - truth.heading_rad).abs());
        let step_pose = Pose2 { x_m: step.x_m, y_m: step.y_m, heading_rad: step.heading_rad };
        if solved {
            f.worst_step_m = f.worst_step_m.max(step_pose.distance(&truth));
            f.worst_heading_rad = f.worst_heading_rad.max((step.heading_rad - truth.heading_rad).abs());
        }
        model = model.compose(&step_pose);
        f.steps += 1;
        f.travelled_m += d;
    }
    f.final_error_m = model.distance(poses.last().expect("a pose"));
    f
}
