//! The closed loop's rig: every service's library in one process, stepped per 50 ms tick in the
//! order of the lockstep clock chain (bridge, sonar, encoders, camera, vision workers, UMS,
//! executive). What a service publishes reaches those after it in the same tick and those
//! before it in the next, as on the bus: the executive's commands go to the vehicle at the start
//! of the next tick, its vision requests are answered on the next frame, the UMS's expectations
//! are searched for on the next frame. Each service's settings are its defaults, or what the
//! mission's launch file gives it.

use std::collections::BTreeMap;

use harvey_denning_bridge::{Bridge, Outgoing, PanicLatch, prioritise, to_drv};
use harvey_encoders::OdometryBuilder;
use harvey_executive::{Executive, Output};
use harvey_geometry::FT;
use harvey_msgs::{
    Encoding, Expectation, FrameHeader, LandmarkSighting, MissionState, MotionCommand, Odometry, Pose2,
    PoseFix, UncertaintyMap, VisionRequest,
};
use harvey_render::{Effects, Renderer, mount_error};
use harvey_sim_drv::SimDrv;
use harvey_sonar::SonarRingBuilder;
use harvey_sonar::avoid::{AvoidParams, PanicAvoid};
use harvey_ums::Ums;
use harvey_vision_workers::VerticalEdges;
use harvey_vision_workers::dispatch::Dispatcher;
use harvey_vision_workers::landmarks::LineLandmarks;
use harvey_world::World;

use crate::launch::Launch;

/// Simulated time per tick (the launch files' `--tick-ms 50`).
pub const TICK_MS: u64 = 50;

/// The vision workers' defaults: vertical edges in a band of 24 rows either side of the centre,
/// edges of 12 grey levels; expectations older than 300 ms are not searched for.
const BAND_HALF_ROWS: u32 = 24;
const EDGE_THRESHOLD: f32 = 12.0;
const EXPECTATION_MAX_AGE_NS: u64 = 300_000_000;

/// The simulated camera: the renderer, its effects, the frame buffer.
struct Camera {
    world: World,
    renderer: Renderer,
    effects: Effects,
    every: u64,
    seq: u64,
    pixels: Vec<u8>,
}

impl Camera {
    /// The frame of this tick's true pose, when one is due (`camera --every`).
    fn shoot(&mut self, tick: u64, pose: Pose2, stamp_ns: u64) -> Option<FrameHeader> {
        if !tick.is_multiple_of(self.every) {
            return None;
        }
        self.seq += 1;
        self.world.set_time(stamp_ns as f64 * 1e-9);
        let r = &self.renderer;
        let h = FrameHeader::new(self.seq, stamp_ns, r.width_px(), r.height_px(), r.encoding());
        self.renderer.render(&self.world, pose, &mut self.pixels).expect("renders");
        let (w, ht, bpp) =
            (h.width_px as usize, h.height_px as usize, (h.stride_bytes / h.width_px) as usize);
        self.effects.apply_at(w, ht, bpp, self.seq, h.stamp_ns, &mut self.pixels);
        Some(h)
    }
}

/// Every service of a mission but the recorder, joined.
pub struct Rig {
    pub sim: SimDrv,
    bridge: Bridge,
    latch: PanicLatch,
    ring: SonarRingBuilder,
    avoid: PanicAvoid,
    encoders: OdometryBuilder,
    camera: Camera,
    dispatcher: Dispatcher,
    edges: VerticalEdges,
    lines: LineLandmarks,
    /// The UMS's expectations the vision workers search for, by landmark.
    wanted: BTreeMap<u32, Expectation>,
    ums: Ums,
    pub exec: Executive,
    /// Published in one tick for services earlier in the chain, which take them the next.
    commands: Vec<MotionCommand>,
    reflexes: Vec<MotionCommand>,
    requests: Vec<VisionRequest>,
    fixes: Vec<PoseFix>,
    odometry: Vec<Odometry>,
    expectations: Vec<Expectation>,
    /// The vision workers' requests not yet answered (standing ones stay).
    asked: BTreeMap<u32, VisionRequest>,
    tick: u64,
    /// Commands the bridge or the vehicle refused.
    pub refused: u32,
    /// The true pose after each tick, with its time (s).
    pub truth: Vec<(f64, Pose2)>,
    /// Everything the executive sent, in order.
    pub sent: Vec<Output>,
}

impl Rig {
    /// The services as `missions/NAME.toml` launches them.
    pub fn new(name: &str) -> Rig {
        let l = Launch::read(name);
        let sim = SimDrv::new(l.world(Some(l.seed), l.sim_movers, l.sim_start), TICK_MS, l.seed);
        let world = l.world(None, false, None);
        let cam_world = l.world(Some(l.camera_seed), l.camera_movers, None);
        let c = &cam_world.camera;
        let (yaw, pitch) = mount_error(c, l.camera_seed);
        let renderer =
            Renderer::new(&cam_world, c.width_px, c.height_px, Encoding::Mono8).misaligned(yaw, pitch);
        let effects = Effects::from_camera(c, l.camera_seed);
        let pixels = vec![0; renderer.frame_bytes()];
        let camera =
            Camera { renderer, effects, every: l.camera_every.max(1), seq: 0, pixels, world: cam_world };
        let stop_m = l.panic_stop_ft * FT;
        // The sonar service's defaults: 8 s to contact over 3 readings, 0.5 ft/s, 90 degrees, 2 ft.
        let avoid = PanicAvoid::new(AvoidParams {
            ttc_s: 8.0,
            confirm: 3,
            min_approach_mps: 0.5 * FT,
            arc_rad: std::f64::consts::FRAC_PI_6,
            turn_rad: std::f64::consts::FRAC_PI_2,
            dash_m: 2.0 * FT,
            stop_m,
        });
        let image_px = (world.camera.width_px, world.camera.height_px);
        // The UMS service's defaults.
        let config = harvey_ums::Config {
            sigmas: 3.0,
            lost_area_m2: 4.0,
            lost_after_misses: 3,
            history_ns: 2_000_000_000,
            image_px,
            fix_m: 0.05,
            fix_heading_rad: 0.5f64.to_radians(),
            mount_gate: None,
        };
        let exec =
            harvey_executive::setup::load(&l.file, Some(&l.world), l.seed).expect("the mission").executive;
        Rig {
            sim,
            bridge: Bridge::default(),
            latch: PanicLatch::new(200_000_000),
            ring: SonarRingBuilder::new(stop_m),
            avoid,
            encoders: OdometryBuilder::default(),
            camera,
            lines: LineLandmarks::new(world.camera.focal_px, EDGE_THRESHOLD)
                .with_calibration_sd(world.survey.calibration_sd_rad),
            dispatcher: Dispatcher::new(world),
            edges: VerticalEdges::new(BAND_HALF_ROWS, EDGE_THRESHOLD),
            wanted: BTreeMap::new(),
            ums: Ums::new(l.world(None, false, l.ums_start), config),
            exec,
            commands: Vec::new(),
            reflexes: Vec::new(),
            requests: Vec::new(),
            fixes: Vec::new(),
            odometry: Vec::new(),
            expectations: Vec::new(),
            asked: BTreeMap::new(),
            tick: 0,
            refused: 0,
            truth: Vec::new(),
            sent: Vec::new(),
        }
    }

    /// Simulated seconds so far.
    pub fn time_s(&self) -> f64 {
        (self.tick * TICK_MS) as f64 / 1000.0
    }

    pub fn running(&self) -> bool {
        self.exec.state() == MissionState::Running
    }

    /// Ticks until the mission ends, `until` says so, or `limit_s` of simulated time have
    /// passed; then five ticks more without the executive (its last commands reach the vehicle).
    pub fn run(&mut self, limit_s: f64, mut until: impl FnMut(&Rig) -> bool) {
        while self.running() && self.time_s() < limit_s && !until(self) {
            self.step();
        }
        for _ in 0..5 {
            self.step();
        }
    }

    /// One tick of the chain.
    pub fn step(&mut self) {
        // denning-bridge: the reflexes' commands first, then the executive's, to the vehicle.
        let mut batch = std::mem::take(&mut self.reflexes);
        batch.extend(self.commands.iter().copied());
        for cmd in prioritise(&batch) {
            match self.latch.admit(&cmd).and_then(|()| to_drv(&cmd)) {
                Ok(drv) => {
                    if matches!(self.sim.handle(drv), harvey_drv_protocol::Report::Nak { .. }) {
                        self.refused += 1;
                    }
                }
                Err(_) => self.refused += 1,
            }
        }
        // sim-drv: the tick; the bridge turns its reports into messages.
        self.tick += 1;
        let out = self.sim.tick();
        let stamp_ns = out.time_ms * 1_000_000;
        self.truth.push((out.time_ms as f64 / 1000.0, out.truth));
        let (mut encoders, mut banks) = (Vec::new(), Vec::new());
        for r in out.reports {
            match self.bridge.on_report(r) {
                Outgoing::Encoders(e) => encoders.push(e),
                Outgoing::Sonar(s) => banks.push(s),
                _ => {}
            }
        }
        // sonar: last tick's odometry, this tick's banks; the ring and the reflexes.
        let mut reflexes = Vec::new();
        for o in std::mem::take(&mut self.odometry) {
            self.ring.on_odometry(&o);
            reflexes.extend(self.avoid.on_odometry(&o));
        }
        let mut rings = Vec::new();
        for bank in &banks {
            let Ok(update) = self.ring.on_bank(bank) else { continue };
            reflexes.extend(update.panic_stop);
            reflexes.extend(self.avoid.on_ring(&update.ring));
            rings.push(update.ring);
        }
        // encoders: the executive's commands of last tick, the reflexes of this one, the reports.
        for c in self.commands.drain(..).chain(reflexes.iter().copied()) {
            self.encoders.on_command(&c);
        }
        let odometry: Vec<Odometry> =
            encoders.iter().filter_map(|e| self.encoders.on_encoders(e).ok()).collect();
        // camera, then the vision workers on the new frame (none on odd ticks: requests wait).
        let frame = self.camera.shoot(self.tick, out.truth, stamp_ns);
        for e in self.expectations.drain(..) {
            self.wanted.insert(e.landmark_index, e);
        }
        for r in self.requests.drain(..) {
            self.asked.insert(r.request_id, r);
        }
        let (mut results, mut sightings, mut detections) = (Vec::new(), Vec::<LandmarkSighting>::new(), 0);
        if let Some(h) = frame {
            let pixels = &self.camera.pixels;
            detections += u64::from(self.edges.run(&h, pixels).is_ok());
            self.lines.focal_px = self.camera.world.camera.focal_for(h.width_px);
            self.wanted.retain(|_, e| e.header.stamp_ns + EXPECTATION_MAX_AGE_NS >= h.stamp_ns);
            sightings.extend(self.wanted.values().filter_map(|e| self.lines.recognise(&h, pixels, e)));
            results.extend(self.asked.values().map(|req| self.dispatcher.answer(&h, pixels, req)));
            self.asked.retain(|_, r| r.standing != 0);
        }
        // ums: this tick's sightings, the executive's fixes of last tick, this tick's odometry.
        for s in &sightings {
            let _ = self.ums.on_sighting(s);
        }
        for f in self.fixes.drain(..) {
            let _ = self.ums.on_fix(&f);
        }
        let mut maps: Vec<UncertaintyMap> = Vec::new();
        for o in &odometry {
            for x in self.ums.on_odometry(o).into_iter().flatten() {
                match x {
                    harvey_ums::Output::Map(m) => maps.push(*m),
                    harvey_ums::Output::Expectation(e) => self.expectations.push(e),
                    harvey_ums::Output::Rejected(_) => {}
                }
            }
        }
        // executive, while the mission runs (the service exits when it ends).
        if self.running() {
            for r in &rings {
                self.exec.on_sonar(r);
            }
            self.exec.on_detections(detections);
            for m in &maps {
                self.exec.on_map(m);
            }
            let mut sent = Vec::new();
            for r in &results {
                sent.extend(self.exec.on_vision(r));
            }
            for o in &odometry {
                sent.extend(self.exec.on_odometry(o));
            }
            for o in &sent {
                match o {
                    Output::Command(c) => self.commands.push(*c),
                    Output::Look(r) => self.requests.push(*r),
                    Output::Pose(p) => self.fixes.push(*p),
                    _ => {}
                }
            }
            self.sent.extend(sent);
        }
        self.odometry = odometry;
        self.reflexes = reflexes;
    }
}
