//! The ums service as a node (`harvey_runtime::Node`): its arguments, ports and turn.
use std::path::PathBuf;

use crate::resume::UmsState;
use crate::{Config, Output, Ums};
use clap::Parser;
use harvey_msgs::{Expectation, LandmarkSighting, Odometry, PoseFix, UncertaintyMap, topics};
use harvey_runtime::{In, Io, Node, Out, Ports, Throttle};

#[derive(Parser)]
#[command(about = "Spatial uncertainty management: the uncertainty map and the Expecter")]
pub struct Args {
    /// World file: terrain statistics, meadows, landmarks, camera.
    #[arg(long)]
    pub world: PathBuf,
    /// Probability of the map in standard deviations (002 §3.1: 2 or 3).
    #[arg(long, default_value_t = 3.0)]
    pub sigmas: f64,
    /// Area above which the robot counts as lost.
    #[arg(long, default_value_t = 4.0)]
    lost_area_m2: f64,
    /// Predicted landmarks missed in a row before the robot counts as lost.
    #[arg(long, default_value_t = 3)]
    pub lost_after_misses: u32,
    /// Where the robot starts, `x_m,y_m,heading_deg`, instead of the world's `[start]` (a
    /// mission's own start).
    #[arg(long)]
    pub start: Option<harvey_world::Pose2>,
    /// A pose fix places the robot within this square's half side (m)…
    #[arg(long, default_value_t = 0.05)]
    pub fix_m: f64,
    /// …and its heading within this either way (degrees).
    #[arg(long, default_value_t = 0.5)]
    pub fix_heading_deg: f64,
    /// How late a sighting may arrive and still be applied at its own stamp.
    #[arg(long, default_value_t = 2000)]
    pub history_ms: u64,
    /// Measure the camera mount's yaw and pitch from the sightings at the start, where the map
    /// still pins the pose, and take them off every sighting (`mount.rs`).
    #[arg(long, default_value_t = false, action = clap::ArgAction::Set)]
    pub calibrate_mount: bool,
    /// A refusal repeated (the same landmark, the same reason) is logged at most once in this
    /// many seconds of message time, with its count.
    #[arg(long, default_value_t = 5.0)]
    pub repeat_warning_s: f64,
}

/// Logs a refusal, unless the same one was logged less than a period ago.
fn warn(throttle: &mut Throttle, e: &dyn std::fmt::Display, stamp_ns: u64) {
    if let Some(said) = throttle.raise(e.to_string(), stamp_ns) {
        tracing::warn!("rejected: {said}");
    }
}

/// The UMS as a node: sightings and fixes first, then the odometry that moves the map on.
pub struct UmsNode {
    odometry: In<Odometry>,
    sightings: In<LandmarkSighting>,
    fixes: In<PoseFix>,
    map_out: Out<UncertaintyMap>,
    expectations: Out<Expectation>,
    ums: Ums,
    repeat_warning_ns: u64,
    odos: Vec<Odometry>,
    seen: Vec<LandmarkSighting>,
    fixed: Vec<PoseFix>,
}

impl Node for UmsNode {
    /// The uncertainty and the warnings held back, as the last finished tick left them.
    type State = (UmsState, Throttle);
    /// Room for the map, its history and the pending sightings.
    const CHECKPOINT_BYTES: usize = 1 << 20;

    fn start(&mut self) -> Self::State {
        (self.ums.state(), Throttle::new(self.repeat_warning_ns))
    }

    fn begin(&mut self, (state, _): &mut Self::State, resumed: bool, _: &mut Io<'_>) -> anyhow::Result<()> {
        if resumed {
            self.ums.restore(state.clone());
            let area_m2 = crate::geometry::area(&self.ums.map().polygon);
            tracing::warn!(area_m2, "resumed from the checkpoint");
        }
        Ok(())
    }

    fn step(&mut self, (_, warnings): &mut Self::State, io: &mut Io<'_>) -> anyhow::Result<()> {
        io.take(self.sightings, &mut self.seen)?;
        for s in &self.seen {
            if let Err(e) = self.ums.on_sighting(s) {
                warn(warnings, &e, s.header.stamp_ns);
            }
        }
        io.take(self.fixes, &mut self.fixed)?;
        for f in &self.fixed {
            if let Err(e) = self.ums.on_fix(f) {
                warn(warnings, &e, f.header.stamp_ns);
            }
        }
        io.take(self.odometry, &mut self.odos)?;
        for o in &self.odos {
            match self.ums.on_odometry(o) {
                Ok(out) => {
                    for x in out {
                        match x {
                            Output::Map(m) => io.send(self.map_out, &m)?,
                            Output::Expectation(e) => io.send(self.expectations, &e)?,
                            Output::Rejected(e) => warn(warnings, &e, o.header.stamp_ns),
                        }
                    }
                }
                Err(e) => warn(warnings, &e, o.header.stamp_ns),
            }
        }
        for said in warnings.expire(io.now()) {
            tracing::warn!("rejected: {said}");
        }
        Ok(())
    }

    fn save(&mut self, (state, _): &mut Self::State) {
        *state = self.ums.state();
    }
}

/// The node the arguments describe, its ports declared on `p`.
pub fn build(args: Args, p: &mut Ports) -> anyhow::Result<UmsNode> {
    anyhow::ensure!(
        args.sigmas > 0.0 && args.lost_area_m2 > 0.0,
        "--sigmas and --lost-area-m2 must be positive"
    );
    anyhow::ensure!(
        args.repeat_warning_s.is_finite() && args.repeat_warning_s >= 0.0,
        "--repeat-warning-s must be a duration in seconds, not {}",
        args.repeat_warning_s
    );
    let mut world = harvey_world::World::load(&args.world)?;
    if let Some(start) = args.start {
        world.start = start;
    }
    let image_px = (world.camera.width_px, world.camera.height_px);
    let config = Config {
        sigmas: args.sigmas,
        lost_area_m2: args.lost_area_m2,
        lost_after_misses: args.lost_after_misses,
        history_ns: args.history_ms * 1_000_000,
        image_px,
        fix_m: args.fix_m,
        fix_heading_rad: args.fix_heading_deg.to_radians(),
        // At the start, while the map knows the heading as well as the survey knows the mount,
        // and the position as well as it knows the map.
        mount_gate: args.calibrate_mount.then(|| crate::mount::Gate {
            heading_rad: world.survey.calibration_sd_rad,
            area_m2: world.survey.position_sd_m.powi(2),
        }),
    };
    let odometry = p.input(topics::ODOMETRY);
    // In real time a turn is as late as the newest of these.
    p.time_from(odometry);
    Ok(UmsNode {
        odometry,
        sightings: p.input(topics::VISION_SIGHTINGS),
        fixes: p.input(topics::EXECUTIVE_POSE),
        map_out: p.output(topics::UMS_MAP),
        expectations: p.output(topics::UMS_EXPECTATIONS),
        ums: Ums::new(world, config),
        repeat_warning_ns: (args.repeat_warning_s * 1e9) as u64,
        odos: Vec::new(),
        seen: Vec::new(),
        fixed: Vec::new(),
    })
}
