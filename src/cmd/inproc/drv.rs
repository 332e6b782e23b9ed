//! The simulated DRV and the denning-bridge in process, on an in-memory line: the bridge's
//! frames go down it encoded as on a serial line, the simulator decodes them, runs its tick and
//! sends its reports back the same way, and the bridge decodes those and publishes them. Both
//! run their own logic ([`harvey_sim_drv::drive`], [`harvey_denning_bridge::link`]), so what
//! they publish is what they publish over a pseudo-terminal.

use clap::Parser;
use harvey_denning_bridge::BridgeState;
use harvey_denning_bridge::link::{BridgePorts, Link, receive, sync};
use harvey_drv_protocol::{Decoder, Line};
use harvey_msgs::{EncodersRaw, LogLine, MissionStatus, MotionCommand, SonarRaw, TruePose, topics};
use harvey_runtime::Rosout;
use harvey_runtime::node::memory::{Hub, Receiver, Sender};
use harvey_sim_drv::drive::Drive;
use harvey_sim_drv::watchdog::HostWatchdog;

use super::chain::Own;

/// The bridge's topics on the hub.
struct OnHub {
    commands: Receiver<MotionCommand>,
    reflexes: Receiver<MotionCommand>,
    heartbeat: Receiver<MissionStatus>,
    encoders: Sender<EncodersRaw>,
    sonar: Sender<SonarRaw>,
    log: Sender<LogLine>,
    /// The tick the DRV's last `TK` closed, until the runner takes it.
    ticked: Option<u64>,
}

impl BridgePorts for OnHub {
    fn commands(&mut self, batch: &mut Vec<MotionCommand>) -> anyhow::Result<usize> {
        self.reflexes.drain(|c| batch.push(c));
        let reflexes = batch.len();
        self.commands.drain(|c| batch.push(c));
        Ok(reflexes)
    }

    fn encoders(&mut self, m: &EncodersRaw) -> anyhow::Result<()> {
        self.encoders.send(*m);
        Ok(())
    }

    fn sonar(&mut self, m: &SonarRaw) -> anyhow::Result<()> {
        self.sonar.send(*m);
        Ok(())
    }

    fn tick(&mut self, rosout: &mut Rosout, time_ms: u64) -> anyhow::Result<()> {
        // As on the bus: the bridge's warnings since the last tick go out before the chain
        // starts on this one.
        let log = &self.log;
        rosout.end_with(time_ms * 1_000_000, |line| {
            log.send(*line);
            Ok(())
        })?;
        rosout.begin();
        self.ticked = Some(time_ms);
        Ok(())
    }
}

type TruthOut = Box<dyn FnMut(&TruePose) -> anyhow::Result<()>>;

/// The simulator, the bridge and the line between them.
pub struct Drv<'a> {
    sim: Drive<TruthOut>,
    /// The bridge on its end of the line; `link.port` holds what it sent and the DRV has not
    /// read yet.
    link: Link<'a, Vec<u8>>,
    ports: OnHub,
    watchdog_ms: u64,
    /// What the DRV sent and the bridge has not read yet.
    from_drv: Vec<u8>,
    sim_decoder: Decoder,
    bridge_decoder: Decoder,
    batch: Vec<MotionCommand>,
    round: Vec<String>,
    /// The host's frames the DRV decoded this round.
    lines: Vec<Line>,
}

/// Service `own`'s arguments as its executable parses them.
fn parse<A: Parser>(own: &Own) -> anyhow::Result<A> {
    let argv = std::iter::once(own.binary.clone()).chain(own.args.iter().cloned());
    A::try_parse_from(argv).map_err(|e| anyhow::anyhow!("service {}: its arguments: {e}", own.name))
}

/// The bridge's state as its arguments start it.
pub fn bridge_state(bridge: &Own) -> anyhow::Result<BridgeState> {
    let a: harvey_denning_bridge::Args = parse(bridge)?;
    Ok(BridgeState::new(a.panic_hold_ms * 1_000_000, a.watchdog_ms * 1_000_000))
}

impl<'a> Drv<'a> {
    /// The simulator service `sim` and bridge service `bridge` describe, the bridge's state in
    /// `state` ([`bridge_state`]), their topics on `hub`.
    pub fn open(sim: &Own, bridge: &Own, state: &'a mut BridgeState, hub: &Hub) -> anyhow::Result<Self> {
        let sim_args: harvey_sim_drv::Args = parse(sim)?;
        let bridge_args: harvey_denning_bridge::Args = parse(bridge)?;
        let truth_pub = hub.publisher::<TruePose>(topics::SIM_TRUTH.name, topics::SIM_TRUTH.qos.buffer)?;
        let truth: TruthOut = Box::new(move |m| {
            truth_pub.send(*m);
            Ok(())
        });
        let watchdog = HostWatchdog::new(sim_args.watchdog_ms);
        let sim = Drive::new(sim_args.simulator()?, watchdog, truth, sim_args.tick_ms, None)?;
        use topics::{
            DRV_ENCODERS_RAW, DRV_SONAR_RAW, EXECUTIVE_STATUS, ROSOUT, VEHICLE_COMMAND, VEHICLE_REFLEX,
        };
        let ports = OnHub {
            commands: hub.subscribe(VEHICLE_COMMAND.name, VEHICLE_COMMAND.qos.buffer)?,
            reflexes: hub.subscribe(VEHICLE_REFLEX.name, VEHICLE_REFLEX.qos.buffer)?,
            heartbeat: hub.subscribe(EXECUTIVE_STATUS.name, EXECUTIVE_STATUS.qos.buffer)?,
            encoders: hub.publisher(DRV_ENCODERS_RAW.name, DRV_ENCODERS_RAW.qos.buffer)?,
            sonar: hub.publisher(DRV_SONAR_RAW.name, DRV_SONAR_RAW.qos.buffer)?,
            log: hub.publisher(ROSOUT.name, ROSOUT.qos.buffer)?,
            ticked: None,
        };
        let rosout = Rosout::detached(&bridge.name);
        rosout.begin();
        Ok(Self {
            sim,
            link: Link { port: Vec::new(), state, checkpoint: None, rosout },
            ports,
            watchdog_ms: bridge_args.watchdog_ms,
            from_drv: Vec::new(),
            sim_decoder: Decoder::new(),
            bridge_decoder: Decoder::new(),
            batch: Vec::new(),
            round: Vec::new(),
            lines: Vec::new(),
        })
    }

    /// One round of the line, the chain having finished tick `t_ns`: the bridge sends the
    /// tick's commands closed by `SY`, the DRV runs the next tick and sends its reports closed
    /// by `TK`, the bridge publishes them. The tick the DRV closed (the chain's next), if it
    /// closed one.
    pub fn round(&mut self, t_ns: u64) -> anyhow::Result<Option<u64>> {
        let link = &mut self.link;
        // The bridge's warnings are its own: captured only while it works, as in its process.
        link.rosout.begin();
        let beats = self.ports.heartbeat.drain(|_| {});
        let commanded = sync(link, &mut self.ports, t_ns / 1_000_000, &mut self.batch, &mut self.round)?;
        if beats > 0 || commanded {
            link.state.watchdog.heartbeat();
        }
        link.rosout.pause();

        // The simulated DRV reads the line (its logs are not the run's, as in its own process).
        let lines = &mut self.lines;
        self.sim_decoder.push(&link.port, |frame| match frame {
            Ok(l) => lines.push(l),
            Err(e) => tracing::warn!("the simulated DRV: bad frame from the host: {e}"),
        });
        link.port.clear();
        for l in self.lines.drain(..) {
            self.sim.on_line(&mut self.from_drv, l, true)?;
        }

        link.rosout.begin();
        let bytes = std::mem::take(&mut self.from_drv);
        receive(self.watchdog_ms, link, &mut self.ports, &mut self.bridge_decoder, &bytes)?;
        link.rosout.pause();
        self.from_drv = bytes;
        self.from_drv.clear();
        Ok(self.ports.ticked.take().map(|ms| ms * 1_000_000))
    }
}
