//! harvey-executive: runs the launch file's `[mission]`, commanding the vehicle and watching
//! odometry, sonar, vision and the uncertainty map; asks the vision workers for the landmarks it
//! servos on. Exits 0 when the mission succeeds, 3 when it fails.

fn main() -> anyhow::Result<std::process::ExitCode> {
    let args = <harvey_executive::node::Args as clap::Parser>::parse();
    harvey_runtime::node::run("executive", |ports| harvey_executive::node::build(args, ports))
}
