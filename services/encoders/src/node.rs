//! The encoders service as a node (`harvey_runtime::Node`): its arguments, ports and turn.
use crate::OdometryBuilder;
use harvey_msgs::{EncodersRaw, MotionCommand, Odometry, topics};
use harvey_runtime::{In, Io, Node, Out, Ports};

/// The encoders service as a node: commands and reflexes first, then the reports they apply to.
pub struct Encoders {
    raw: In<EncodersRaw>,
    commands: In<MotionCommand>,
    reflexes: In<MotionCommand>,
    odometry: Out<Odometry>,
    reports: Vec<EncodersRaw>,
    cmds: Vec<MotionCommand>,
}

impl Node for Encoders {
    type State = OdometryBuilder;
    /// Room for the builder and the marks of its three inputs.
    const CHECKPOINT_BYTES: usize = 4 << 10;

    fn start(&mut self) -> OdometryBuilder {
        OdometryBuilder::default()
    }

    fn step(&mut self, builder: &mut OdometryBuilder, io: &mut Io<'_>) -> anyhow::Result<()> {
        for input in [self.commands, self.reflexes] {
            io.take(input, &mut self.cmds)?;
            self.cmds.iter().for_each(|c| builder.on_command(c));
        }
        io.take(self.raw, &mut self.reports)?;
        for r in &self.reports {
            match builder.on_encoders(r) {
                Ok(odo) => io.send(self.odometry, &odo)?,
                Err(e) => tracing::warn!("dropping an encoder report: {e}"),
            }
        }
        Ok(())
    }
}

/// The node the arguments describe, its ports declared on `p`.
pub fn build(p: &mut Ports) -> anyhow::Result<Encoders> {
    let raw = p.input(topics::DRV_ENCODERS_RAW);
    // In real time a turn is as late as the newest of these.
    p.time_from(raw);
    Ok(Encoders {
        raw,
        commands: p.input(topics::VEHICLE_COMMAND),
        reflexes: p.input(topics::VEHICLE_REFLEX),
        odometry: p.output(topics::ODOMETRY),
        reports: Vec::new(),
        cmds: Vec::new(),
    })
}
