//! harvey-executive: runs the launch file's `[mission]`, commanding the vehicle and watching
//! odometry, sonar, vision and the uncertainty map; asks the vision workers for the landmarks it
//! servos on. Exits 0 when the mission succeeds, 3 when it fails.

use std::path::PathBuf;

use clap::Parser;
use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_executive::{Executive, Output, setup};
use harvey_msgs::{MissionState, Odometry, SonarRing, UncertaintyMap, VisionResult, topics};
use harvey_runtime::{Journal, Marks, Sent};

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

/// Sends `m` unless a predecessor of this process sent it before it was killed.
fn send<T: harvey_msgs::Message>(
    sent: &mut Sent,
    port: &harvey_bus::Publisher<T>,
    m: &T,
) -> anyhow::Result<()> {
    let h = *m.header();
    if sent.due(port.topic(), h.stamp_ns, h.seq) {
        port.send(m)?;
        sent.done(port.topic(), h.stamp_ns, h.seq)?;
    }
    Ok(())
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

    /// The tick back, its messages noted taken.
    fn decode(&self, marks: &mut Marks) -> anyhow::Result<Tick> {
        fn back<T: harvey_cdr::Cdr + harvey_msgs::Message>(
            v: &[Vec<u8>],
            topic: &str,
            marks: &mut Marks,
        ) -> anyhow::Result<Vec<T>> {
            v.iter()
                .map(|b| {
                    let m: T =
                        harvey_cdr::decode(b).map_err(|e| anyhow::anyhow!("the journal's {topic}: {e}"))?;
                    marks.fresh(topic, m.header().stamp_ns, m.header().seq);
                    Ok(m)
                })
                .collect()
        }
        if let Some((stamp, seq)) = self.newest_detection {
            marks.fresh(topics::VISION_DETECTIONS.name, stamp, seq);
        }
        Ok(Tick {
            rings: back(&self.rings, topics::SONAR_RING.name, marks)?,
            detections: self.detections,
            newest_detection: self.newest_detection,
            maps: back(&self.maps, topics::UMS_MAP.name, marks)?,
            results: back(&self.results, topics::VISION_RESULTS.name, marks)?,
            odos: back(&self.odos, topics::ODOMETRY.name, marks)?,
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

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let loaded = setup::load(&args.mission, args.world.as_deref(), args.seed)?;
    let mission = &loaded.mission;
    tracing::info!(description = %mission.description, steps = mission.steps.len(), "mission loaded");
    let mut exec = loaded.executive;

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
    let mut rosout = harvey_runtime::Rosout::new(&bus, "executive")?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&odometry, &sonar, &detections, &maps, &results])?;
    harvey_runtime::notify_ready()?;

    // A restarted executive is rebuilt by running its predecessor's inputs through it again
    // (its plans and behaviours are too rich to checkpoint; the logic is deterministic).
    let mut marks = Marks::default();
    let mut journal = match Journal::from_env::<Journaled>("executive")? {
        Some((journal, past)) => {
            if !past.is_empty() {
                let ticks = past.len();
                for j in past {
                    let tick = j.decode(&mut marks)?;
                    let _ = step(&mut exec, &tick);
                }
                tracing::warn!(ticks, state = ?exec.state(), "resumed: the inputs of the ticks before run through again");
            }
            Some(journal)
        }
        None => None,
    };
    let mut sent = Sent::from_env("executive")?;
    let mut tick = Tick::default();
    let mut latest_ns = 0;
    while exec.state() == MissionState::Running {
        let turn = match pace.next(&waiter, None)? {
            Step::Go(turn) => turn,
            Step::Idle => continue,
            Step::Stop => {
                tracing::warn!("stopped before the mission ended");
                return Ok(());
            }
        };
        rosout.begin();
        let fresh =
            |marks: &mut Marks, topic: &str, h: &harvey_msgs::Header| marks.fresh(topic, h.stamp_ns, h.seq);
        sonar.drain_into(&mut tick.rings)?;
        tick.rings.retain(|m| fresh(&mut marks, sonar.topic(), &m.header));
        let (mut n, mut newest) = (0, None);
        detections.drain(|d| {
            if fresh(&mut marks, detections.topic(), &d.header) {
                (n, newest) = (n + 1, Some((d.header.stamp_ns, d.header.seq)));
            }
        })?;
        (tick.detections, tick.newest_detection) = (n, newest);
        maps.drain_into(&mut tick.maps)?;
        tick.maps.retain(|m| fresh(&mut marks, maps.topic(), &m.header));
        results.drain_into(&mut tick.results)?;
        tick.results.retain(|m| fresh(&mut marks, results.topic(), &m.header));
        odometry.drain_into(&mut tick.odos)?;
        tick.odos.retain(|m| fresh(&mut marks, odometry.topic(), &m.header));
        latest_ns = tick.odos.iter().map(|o| o.header.stamp_ns).fold(latest_ns, u64::max);
        let out = step(&mut exec, &tick);
        for o in &out {
            match o {
                Output::Command(c) => {
                    tracing::debug!(
                        id = c.command_id,
                        kind = c.kind,
                        distance_m = c.distance_m,
                        angle_rad = c.angle_rad,
                        "command"
                    );
                    send(&mut sent, &commands, c)?;
                }
                Output::Look(r) => {
                    send(&mut sent, &requests, r)?;
                }
                Output::Status(s) => {
                    send(&mut sent, &status, s)?;
                }
                Output::Servo(c) => {
                    send(&mut sent, &servo_pub, c)?;
                }
                Output::Pose(p) => {
                    send(&mut sent, &pose_pub, p)?;
                }
                Output::Plan(p) => {
                    send(&mut sent, &plan_pub, p)?;
                }
                Output::Behaviour(b) => {
                    send(&mut sent, &behaviour_pub, b)?;
                }
            }
        }
        rosout.end(turn.unwrap_or(latest_ns))?;
        if let Some(j) = journal.as_mut() {
            j.append(&Journaled::encode(&tick))?;
        }
        pace.done()?;
    }
    summarise(&exec)
}

/// Logs the servoed legs and exits as the mission ended.
fn summarise(exec: &Executive) -> anyhow::Result<()> {
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
            Ok(())
        }
        _ => {
            tracing::error!("mission failed");
            std::process::exit(3)
        }
    }
}
