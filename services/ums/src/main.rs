//! harvey-ums: odometry and landmark sightings in; the uncertainty map and the Expecter's
//! windows out.

fn main() -> anyhow::Result<std::process::ExitCode> {
    let args = <harvey_ums::node::Args as clap::Parser>::parse();
    harvey_runtime::node::run("ums", |ports| harvey_ums::node::build(args, ports))
}
