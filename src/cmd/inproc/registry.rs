//! The services that can run in process, by executable name: each one's node, built from the
//! arguments its launch line gives.

use clap::Parser;
use harvey_runtime::node::memory::Hub;
use harvey_runtime::node::{Hosted, host};

/// Services with a node registered for in-process runs (by executable name).
pub const IN_PROCESS: [&str; 6] = [
    "harvey-sonar",
    "harvey-encoders",
    "harvey-camera",
    "harvey-vision-workers",
    "harvey-ums",
    "harvey-executive",
];

/// The node of service `name` (executable `binary`) with arguments `args`, its ports on `hub`.
pub fn node(name: &str, binary: &str, args: &[String], hub: &Hub) -> anyhow::Result<Box<dyn Hosted>> {
    let argv = || std::iter::once(binary.to_owned()).chain(args.iter().cloned());
    let parsed = |e: clap::Error| anyhow::anyhow!("service {name}: its arguments: {e}");
    match binary {
        "harvey-sonar" => {
            let a = harvey_sonar::node::Args::try_parse_from(argv()).map_err(parsed)?;
            host(name, hub, |p| harvey_sonar::node::build(a, p))
        }
        "harvey-encoders" => host(name, hub, harvey_encoders::node::build),
        "harvey-camera" => {
            let a = harvey_camera::node::Args::try_parse_from(argv()).map_err(parsed)?;
            host(name, hub, |p| harvey_camera::node::build(a, p))
        }
        "harvey-vision-workers" => {
            let a = harvey_vision_workers::node::Args::try_parse_from(argv()).map_err(parsed)?;
            host(name, hub, |p| harvey_vision_workers::node::build(a, p))
        }
        "harvey-ums" => {
            let a = harvey_ums::node::Args::try_parse_from(argv()).map_err(parsed)?;
            host(name, hub, |p| harvey_ums::node::build(a, p))
        }
        "harvey-executive" => {
            let a = harvey_executive::node::Args::try_parse_from(argv()).map_err(parsed)?;
            host(name, hub, |p| harvey_executive::node::build(a, p))
        }
        other => anyhow::bail!(
            "service {name} ({other}) has no node registered for in-process runs; these can run in \
             process: {}",
            IN_PROCESS.join(", ")
        ),
    }
}
