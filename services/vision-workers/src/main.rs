//! harvey-vision-workers: runs perceptual algorithms on camera frames read in place from shared
//! memory: vertical edges across the frame, and the landmarks the Expecter asks for, inside
//! their windows.

fn main() -> anyhow::Result<std::process::ExitCode> {
    let args = <harvey_vision_workers::node::Args as clap::Parser>::parse();
    harvey_runtime::node::run("vision-workers", |ports| harvey_vision_workers::node::build(args, ports))
}
