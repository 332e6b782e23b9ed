//! harvey-sonar: raw DRV sonar banks in, the 24-sensor ring out; the panic-stop and panic-avoid
//! reflexes' commands go straight to the vehicle (001 §6.2). The ring and the reflexes' state are
//! checkpointed every tick, so a restarted sonar service goes on where it was.

fn main() -> anyhow::Result<std::process::ExitCode> {
    let args = <harvey_sonar::node::Args as clap::Parser>::parse();
    harvey_runtime::node::run("sonar", |ports| harvey_sonar::node::build(args, ports))
}
