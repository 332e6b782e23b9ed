//! harvey-encoders: DRV shaft-encoder reports and motion commands in, odometry out. Its state
//! (the command under way and where it started) is checkpointed at every tick, so a restarted
//! encoders service goes on with the same command.

fn main() -> anyhow::Result<std::process::ExitCode> {
    harvey_runtime::node::run("encoders", harvey_encoders::node::build)
}
