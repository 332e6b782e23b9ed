//! harvey-executive: runs the launch file's `[mission]`, commanding the vehicle and watching
//! odometry, sonar, vision and the uncertainty map; asks the vision workers for the landmarks it
//! servos on. Exits 0 when the mission succeeds, 3 when it fails.

use std::path::PathBuf;

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_executive::behaviour::Behaviour;
use harvey_executive::docking::Docking;
use harvey_executive::fsa::Fsa;
use harvey_executive::leg::ServoSetup;
use harvey_executive::mission::Mission;
use harvey_executive::monitor::Monitor;
use harvey_executive::pole_hunt::PoleHunt;
use harvey_executive::pose::{PinholeCamera, RefineParams};
use harvey_executive::refining::RefineSetup;
use harvey_executive::servo::ServoParams;
use harvey_executive::{Executive, Output, mission};
use harvey_msgs::{MissionState, topics};
use harvey_world::World;

#[derive(Parser)]
#[command(about = "Mission executive")]
struct Args {
    /// The launch file holding the `[mission]` table.
    #[arg(long)]
    mission: PathBuf,
    /// The world file (needed by missions that servo on landmarks).
    #[arg(long)]
    world: Option<PathBuf>,
    /// Seed of the noise motor schema.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// How each step servos: its landmark looked up in the world, the camera from its calibration.
fn servo_setups(m: &Mission, world: Option<&World>) -> anyhow::Result<Vec<Option<ServoSetup>>> {
    m.steps
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let (Some(name), Some(sv)) = (&s.servo_landmark, m.servo) else { return Ok(None) };
            let w = world.with_context(|| format!("mission.step[{i}] servos on {name}: pass --world"))?;
            let (index, l) = w
                .landmarks
                .iter()
                .enumerate()
                .find(|(_, l)| &l.name == name)
                .with_context(|| format!("mission.step[{i}]: no landmark {name} in world {}", w.name))?;
            let base = l.point();
            let v = s.servo_vertex_m;
            Ok(Some(ServoSetup {
                landmark_index: index as u32,
                point: [base[0] + v[0], base[1] + v[1], base[2] + v[2]],
                offset: v,
                params: ServoParams {
                    focal_px: w.camera.focal_for(w.camera.width_px),
                    misalignment_rad: sv.misalignment_deg.to_radians(),
                    aim_m: sv.aim_m,
                },
                width_px: w.camera.width_px,
                height_px: w.camera.height_px,
                camera_height_m: w.camera.height_m,
                tracking: sv.offset,
            }))
        })
        .collect()
}

/// What plan-level servoing needs: each vertex anchored on the nearest landmark (the vision
/// request names a landmark and an offset from its point), and the camera.
fn refine_setup(m: &Mission, world: Option<&World>) -> anyhow::Result<Option<RefineSetup>> {
    let Some(r) = &m.refine else { return Ok(None) };
    let w = world.context("[mission.refine] needs --world")?;
    let vertices = r
        .vertices_m
        .iter()
        .map(|&v| {
            let dist = |p: [f64; 3]| (0..3).map(|k| (p[k] - v[k]).powi(2)).sum::<f64>();
            let (i, l) = w
                .landmarks
                .iter()
                .enumerate()
                .min_by(|a, b| dist(a.1.point()).total_cmp(&dist(b.1.point())))
                .context("the world has no landmark to anchor vertices on")?;
            let p = l.point();
            Ok((i as u32, [v[0] - p[0], v[1] - p[1], v[2] - p[2]], v))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let c = &w.camera;
    Ok(Some(RefineSetup {
        vertices,
        camera: PinholeCamera {
            focal_px: c.focal_for(c.width_px),
            centre_px: [f64::from(c.width_px) / 2.0, f64::from(c.height_px) / 2.0],
            height_m: c.height_m,
        },
        params: RefineParams {
            prior_sd: [r.prior_sd[0], r.prior_sd[1], r.prior_sd[2].to_radians()],
            image_sd_px: 0.5,
            gate_px: r.gate_px,
        },
        template_px: r.template_px,
        min_score: r.min_score,
        max_sd_m: r.max_sd_m.unwrap_or(f64::INFINITY),
        world: Some(w.clone()),
    }))
}

/// An acceptor (a file next to the launch file) that has state `done`.
fn acceptor(args: &Args, file: &str, done: &str) -> anyhow::Result<Fsa> {
    let path = args.mission.parent().unwrap_or(std::path::Path::new(".")).join(file);
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let fsa = Fsa::parse(&text, &path.display().to_string()).map_err(anyhow::Error::msg)?;
    anyhow::ensure!(fsa.states.iter().any(|s| s.name == done), "{}: no state {done}", path.display());
    Ok(fsa)
}

/// The docking behaviour or the pole hunt: the acceptor, the camera, the sonar, the seed.
fn behaviour_setup(m: &Mission, world: Option<&World>, args: &Args) -> anyhow::Result<Option<Behaviour>> {
    if m.docking.is_none() && m.poles.is_none() {
        return Ok(None);
    }
    let w = world.context("[mission.docking] and [mission.poles] need --world")?;
    let c = &w.camera;
    let (focal, width, height) = (c.focal_for(c.width_px), f64::from(c.width_px), f64::from(c.height_px));
    let ring = w.robot.sonar_ring_radius_m;
    if let Some(g) = &m.docking {
        let fsa = acceptor(args, &g.fsa, &g.docked_state)?;
        let d = Docking::new(g.clone(), fsa, (focal, width, height), ring, args.seed);
        return Ok(Some(Behaviour::Docking(Box::new(d))));
    }
    let Some(g) = &m.poles else { return Ok(None) };
    let fsa = acceptor(args, &g.fsa, &g.parked_state)?;
    let poles =
        w.poles.as_ref().with_context(|| format!("[mission.poles]: world {} has no [poles]", w.name))?;
    let s = w.start;
    let start = harvey_msgs::Pose2 { x_m: s.x_m, y_m: s.y_m, heading_rad: s.heading_deg.to_radians() };
    let hunt = PoleHunt::new(g.clone(), fsa, (focal, width), ring, poles.side_m, args.seed, start);
    Ok(Some(Behaviour::Poles(Box::new(hunt))))
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let text = std::fs::read_to_string(&args.mission)
        .with_context(|| format!("reading {}", args.mission.display()))?;
    let mission = mission::parse(&text, &args.mission.display().to_string()).map_err(anyhow::Error::msg)?;
    let world = args.world.as_deref().map(World::load).transpose()?;
    let servo = servo_setups(&mission, world.as_ref())?;
    let refine = refine_setup(&mission, world.as_ref())?;
    let exec_goal = match &mission.ptrans {
        Some(goal) => {
            let w = world.clone().context("[mission.ptrans] needs --world")?;
            anyhow::ensure!(
                w.locales.iter().any(|l| l.name == goal.to),
                "[mission.ptrans] goes to locale {}, which world {} lacks",
                goal.to,
                w.name
            );
            Some(Monitor::new(goal.clone(), w))
        }
        None => None,
    };
    let behaviour = behaviour_setup(&mission, world.as_ref(), &args)?;
    tracing::info!(description = %mission.description, steps = mission.steps.len(), "mission loaded");

    let bus = Bus::join("executive")?;
    let odometry = bus.subscriber(topics::ODOMETRY)?;
    let sonar = bus.subscriber(topics::SONAR_RING)?;
    let detections = bus.subscriber(topics::VISION_DETECTIONS)?;
    let maps = bus.subscriber(topics::UMS_MAP)?;
    let results = bus.subscriber(topics::VISION_RESULTS)?;
    let commands = bus.publisher(topics::VEHICLE_COMMAND)?;
    let status = bus.publisher(topics::EXECUTIVE_STATUS)?;
    let requests = bus.publisher(topics::VISION_REQUESTS)?;
    let servo_pub = bus.publisher(topics::EXECUTIVE_SERVO)?;
    let pose_pub = bus.publisher(topics::EXECUTIVE_POSE)?;
    let behaviour_pub = bus.publisher(topics::EXECUTIVE_BEHAVIOUR)?;
    let plan_pub = bus.publisher(topics::EXECUTIVE_PLAN)?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&odometry, &sonar, &detections, &maps, &results])?;
    harvey_runtime::notify_ready()?;

    let mut exec = Executive::new(mission, servo);
    if let Some(setup) = refine {
        exec = exec.with_refine(setup);
    }
    if let Some(goal) = exec_goal {
        exec = exec.with_plan(goal);
    }
    if let Some(b) = behaviour {
        exec = exec.with_behaviour(b);
    }
    let (mut odos, mut seen, mut rings, mut map_batch) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut out = Vec::new();
    while exec.state() == MissionState::Running {
        if pace.next(&waiter, None)? == Step::Stop {
            tracing::warn!("stopped before the mission ended");
            return Ok(());
        }
        sonar.drain_into(&mut rings)?;
        for r in &rings {
            exec.on_sonar(r);
        }
        exec.detections_seen += detections.drain(|_| {})? as u64;
        maps.drain_into(&mut map_batch)?;
        for m in &map_batch {
            exec.on_map(m);
        }
        results.drain_into(&mut seen)?;
        odometry.drain_into(&mut odos)?;
        out.clear();
        for r in &seen {
            out.extend(exec.on_vision(r));
        }
        for o in &odos {
            out.extend(exec.on_odometry(o));
        }
        for o in &out {
            match o {
                Output::Command(c) => {
                    tracing::info!(
                        id = c.command_id,
                        kind = c.kind,
                        distance_m = c.distance_m,
                        angle_rad = c.angle_rad,
                        "command"
                    );
                    commands.send(c)?;
                }
                Output::Look(r) => {
                    requests.send(r)?;
                }
                Output::Status(s) => {
                    status.send(s)?;
                }
                Output::Servo(c) => {
                    servo_pub.send(c)?;
                }
                Output::Pose(p) => {
                    pose_pub.send(p)?;
                }
                Output::Plan(p) => {
                    plan_pub.send(p)?;
                }
                Output::Behaviour(b) => {
                    behaviour_pub.send(b)?;
                }
            }
        }
        pace.done()?;
    }
    for (k, leg) in exec.legs.iter().enumerate() {
        let worst = leg.corrections.iter().map(|c| c.1.abs()).fold(0.0, f64::max);
        tracing::info!(
            leg = k,
            corrections = leg.corrections.len(),
            misses = leg.misses,
            largest_correction_deg = worst.to_degrees(),
            "servoed leg"
        );
    }
    match exec.state() {
        MissionState::Succeeded => {
            tracing::info!("mission succeeded");
            Ok(())
        }
        _ => {
            tracing::error!("mission failed");
            std::process::exit(3)
        }
    }
}
