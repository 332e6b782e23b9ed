//! `harvey launch FILE`: the supervisor on a launch file, until its `end_with` service exits or
//! a signal stops it.

use std::path::Path;

use super::{LaunchArgs, launch_file, launch_options};

pub fn run(file: &Path, opts: &LaunchArgs) -> anyhow::Result<i32> {
    let (outcome, _) = launch_file(file, opts)?;
    println!("launch: {outcome:?}");
    Ok(outcome.exit_code())
}

/// `harvey supervise FILE`: the supervisor process of a launch, started by its keeper (the
/// `harvey run`/`launch`/`replay` process) with the keeper's line on an inherited descriptor.
pub fn supervise(file: &Path, args: &LaunchArgs) -> anyhow::Result<i32> {
    let Some(mut line) = harvey_supervisor::KeeperLine::from_env()? else {
        anyhow::bail!("`harvey supervise` runs under a keeper: use `harvey launch {}`", file.display());
    };
    let mut lf = harvey_supervisor::LaunchFile::load(file)?;
    if args.realtime {
        lf.settings.clock = harvey_supervisor::ClockMode::Realtime;
    }
    if let Some(addr) = &args.foxglove {
        // First: it is listening before anything publishes, and is stopped last.
        lf.services.insert(0, super::live::foxglove_service(addr, lf.settings.world.is_some())?);
    }
    if let Some(host) = &args.host {
        super::hosts::place(&mut lf, host, &args.zenoh_listen, &args.zenoh_connect)?;
    } else if args.zenoh() {
        // First, as the Foxglove bridge: its peers connect before anything publishes. In a
        // deterministic launch it is the party before the recorder (the chain wraps round).
        lf.services.insert(
            0,
            super::zenoh::zenoh_service(&args.zenoh_listen, &args.zenoh_connect, args.ros2_domain)?,
        );
    }
    let outcome = harvey_supervisor::run(&lf, &launch_options(&lf, args), &mut line)?;
    line.report(&outcome)?;
    Ok(outcome.exit_code())
}
