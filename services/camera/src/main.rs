//! harvey-camera: renders the simulated world into loaned shared-memory frames, from the
//! simulator's true pose (`sim/truth`), or from a fixed pose at a fixed rate (`--pose`), or
//! plays a folder of images (`--images`).

use harvey_camera::node;

fn main() -> anyhow::Result<std::process::ExitCode> {
    let args = <node::Args as clap::Parser>::parse();
    harvey_runtime::node::run("camera", |ports| node::build(args, ports))
}
