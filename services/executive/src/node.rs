//! The executive service as a node (`harvey_runtime::Node`): its arguments, ports and turn.
use std::path::PathBuf;

use clap::Parser;

use crate::{Executive, Output, setup};
use harvey_msgs::{
    BehaviourState, Detections, Message, MissionState, MissionStatus, MotionCommand, Odometry, PlanSketch,
    PoseFix, ServoCorrection, SonarRing, UncertaintyMap, VisionRequest, VisionResult, topics,
};
use harvey_runtime::{End, In, Io, Journal, Node, Out, Ports};

#[derive(Parser)]
#[command(about = "Mission executive")]
pub struct Args {
    /// The launch file holding the `[mission]` table.
    #[arg(long)]
    pub mission: PathBuf,
    /// The world file (needed by missions that servo on landmarks).
    #[arg(long)]
    pub world: Option<PathBuf>,
    /// Seed of the noise motor schema.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// One tick's inputs, as the executive takes them.
#[derive(Default)]
struct Tick {
    rings: Vec<SonarRing>,
    detections: u64,
    /// (stamp, seq) of the newest detection counted (the executive counts them only).
    newest_detection: Option<(u64, u64)>,
    maps: Vec<UncertaintyMap>,
    results: Vec<VisionResult>,
    odos: Vec<Odometry>,
}

/// A tick's inputs in the journal, each message as its CDR.
#[derive(serde::Serialize, serde::Deserialize)]
struct Journaled {
    rings: Vec<Vec<u8>>,
    detections: u64,
    newest_detection: Option<(u64, u64)>,
    maps: Vec<Vec<u8>>,
    results: Vec<Vec<u8>>,
    odos: Vec<Vec<u8>>,
}

impl Journaled {
    fn encode(t: &Tick) -> Self {
        fn cdr<T: harvey_cdr::Cdr>(v: &[T]) -> Vec<Vec<u8>> {
            v.iter().map(|m| harvey_cdr::encode(m, Vec::new())).collect()
        }
        Self {
            rings: cdr(&t.rings),
            detections: t.detections,
            newest_detection: t.newest_detection,
            maps: cdr(&t.maps),
            results: cdr(&t.results),
            odos: cdr(&t.odos),
        }
    }

    /// The tick back.
    fn decode(&self) -> anyhow::Result<Tick> {
        fn back<T: harvey_cdr::Cdr>(v: &[Vec<u8>], topic: &str) -> anyhow::Result<Vec<T>> {
            v.iter()
                .map(|b| harvey_cdr::decode(b).map_err(|e| anyhow::anyhow!("the journal's {topic}: {e}")))
                .collect()
        }
        Ok(Tick {
            rings: back(&self.rings, topics::SONAR_RING.name)?,
            detections: self.detections,
            newest_detection: self.newest_detection,
            maps: back(&self.maps, topics::UMS_MAP.name)?,
            results: back(&self.results, topics::VISION_RESULTS.name)?,
            odos: back(&self.odos, topics::ODOMETRY.name)?,
        })
    }
}

/// The executive's turn on one tick's inputs.
fn step(exec: &mut Executive, t: &Tick) -> Vec<Output> {
    for r in &t.rings {
        exec.on_sonar(r);
    }
    exec.on_detections(t.detections);
    for m in &t.maps {
        exec.on_map(m);
    }
    let mut out = Vec::new();
    for r in &t.results {
        out.extend(exec.on_vision(r));
    }
    for o in &t.odos {
        out.extend(exec.on_odometry(o));
    }
    out
}

/// The executive as a node: its inputs in the order it takes them, its outputs, and the journal
/// a restarted executive is rebuilt from.
pub struct ExecutiveNode {
    sonar: In<SonarRing>,
    detections: In<Detections>,
    maps: In<UncertaintyMap>,
    results: In<VisionResult>,
    odometry: In<Odometry>,
    commands: Out<MotionCommand>,
    status: Out<MissionStatus>,
    requests: Out<VisionRequest>,
    servo: Out<ServoCorrection>,
    pose: Out<PoseFix>,
    behaviour: Out<BehaviourState>,
    plan: Out<PlanSketch>,
    exec: Executive,
    journal: Option<Journal>,
    tick: Tick,
    seen: Vec<Detections>,
}

impl ExecutiveNode {
    /// Notes a journaled tick's messages taken, so that their re-offers are not taken again.
    fn mark(&self, io: &mut Io<'_>, t: &Tick) {
        fn all<T: Message>(io: &mut Io<'_>, input: In<T>, msgs: &[T]) {
            msgs.iter().for_each(|m| io.mark_taken(input, m.header().stamp_ns, m.header().seq));
        }
        all(io, self.sonar, &t.rings);
        if let Some((s, q)) = t.newest_detection {
            io.mark_taken(self.detections, s, q);
        }
        all(io, self.maps, &t.maps);
        all(io, self.results, &t.results);
        all(io, self.odometry, &t.odos);
    }
}

impl Node for ExecutiveNode {
    /// Nothing is checkpointed: plans and behaviours are too rich, so a restarted executive runs
    /// its predecessor's inputs through again (the logic is deterministic).
    type State = ();
    const CHECKPOINT_BYTES: usize = 0;

    fn start(&mut self) {}

    fn begin(&mut self, _: &mut (), _: bool, io: &mut Io<'_>) -> anyhow::Result<()> {
        if !io.persistent() {
            return Ok(());
        }
        let Some((journal, past)) = Journal::from_env::<Journaled>("executive")? else {
            return Ok(());
        };
        self.journal = Some(journal);
        if !past.is_empty() {
            let ticks = past.len();
            for j in past {
                let tick = j.decode()?;
                self.mark(io, &tick);
                let _ = step(&mut self.exec, &tick);
            }
            tracing::warn!(ticks, state = ?self.exec.state(), "resumed: the inputs of the ticks before run through again");
        }
        Ok(())
    }

    fn finished(&self, _: &()) -> bool {
        self.exec.state() != MissionState::Running
    }

    fn step(&mut self, _: &mut (), io: &mut Io<'_>) -> anyhow::Result<()> {
        let t = &mut self.tick;
        io.take(self.sonar, &mut t.rings)?;
        io.take(self.detections, &mut self.seen)?;
        t.detections = self.seen.len() as u64;
        t.newest_detection = self.seen.last().map(|d| (d.header.stamp_ns, d.header.seq));
        io.take(self.maps, &mut t.maps)?;
        io.take(self.results, &mut t.results)?;
        io.take(self.odometry, &mut t.odos)?;
        for o in step(&mut self.exec, t) {
            match o {
                Output::Command(c) => {
                    tracing::debug!(
                        id = c.command_id,
                        kind = c.kind,
                        distance_m = c.distance_m,
                        angle_rad = c.angle_rad,
                        "command"
                    );
                    io.send(self.commands, &c)?;
                }
                Output::Look(r) => io.send(self.requests, &r)?,
                Output::Status(s) => io.send(self.status, &s)?,
                Output::Servo(c) => io.send(self.servo, &c)?,
                Output::Pose(p) => io.send(self.pose, &p)?,
                Output::Plan(p) => io.send(self.plan, &p)?,
                Output::Behaviour(b) => io.send(self.behaviour, &b)?,
            }
        }
        if let Some(j) = self.journal.as_mut() {
            j.append(&Journaled::encode(&self.tick))?;
        }
        Ok(())
    }

    fn stopped(&mut self, _: &(), end: End) -> anyhow::Result<u8> {
        if end == End::Stopped {
            tracing::warn!("stopped before the mission ended");
            return Ok(0);
        }
        Ok(summarise(&self.exec))
    }
}

/// The node the arguments describe, its ports declared on `p`.
pub fn build(args: Args, p: &mut Ports) -> anyhow::Result<ExecutiveNode> {
    let loaded = setup::load(&args.mission, args.world.as_deref(), args.seed)?;
    let mission = &loaded.mission;
    tracing::info!(description = %mission.description, steps = mission.steps.len(), "mission loaded");
    let odometry = p.input(topics::ODOMETRY);
    // In real time a turn is as late as the newest of these.
    p.time_from(odometry);
    Ok(ExecutiveNode {
        sonar: p.input(topics::SONAR_RING),
        detections: p.input(topics::VISION_DETECTIONS),
        maps: p.input(topics::UMS_MAP),
        results: p.input(topics::VISION_RESULTS),
        odometry,
        commands: p.output(topics::VEHICLE_COMMAND),
        status: p.output(topics::EXECUTIVE_STATUS),
        requests: p.output(topics::VISION_REQUESTS),
        servo: p.output(topics::EXECUTIVE_SERVO),
        pose: p.output(topics::EXECUTIVE_POSE),
        behaviour: p.output(topics::EXECUTIVE_BEHAVIOUR),
        plan: p.output(topics::EXECUTIVE_PLAN),
        exec: loaded.executive,
        journal: None,
        tick: Tick::default(),
        seen: Vec::new(),
    })
}

/// Logs the servoed legs; the exit code as the mission ended (0 succeeded, 3 failed).
fn summarise(exec: &Executive) -> u8 {
    for (k, leg) in exec.legs().iter().enumerate() {
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
            0
        }
        _ => {
            tracing::error!("mission failed");
            3
        }
    }
}
