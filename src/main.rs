//! harvey: the command line — run the default mission, launch a launch file under the
//! supervisor, and inspect recordings. The arguments are here; each command is a file of
//! `cmd/`.

mod cmd;
mod summary;

use std::path::PathBuf;

use clap::{Parser, Subcommand};
use cmd::LaunchArgs;
use tracing_subscriber::Layer;
use tracing_subscriber::layer::SubscriberExt;
use tracing_subscriber::util::SubscriberInitExt;

#[derive(Parser)]
#[command(name = "harvey", version, about = "Harvey robotics stack: missions, supervisor and recordings")]
struct Cli {
    #[command(subcommand)]
    command: Option<Cmd>,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run a mission (default: missions/default.toml), record it and print its summary.
    Run {
        mission: Option<PathBuf>,
        /// Run every service in this one process, one thread, on in-memory topics (the
        /// simulated DRV and the bridge on an in-memory serial line): the same recording as under
        /// the supervisor, with no processes and no shared memory (deterministic launches).
        #[arg(long, conflicts_with_all = ["live", "foxglove", "realtime", "zenoh_listen", "zenoh_connect", "host", "ros2_domain"])]
        in_process: bool,
        #[command(flatten)]
        opts: LaunchArgs,
    },
    /// Run a launch file under the supervisor.
    Launch {
        file: PathBuf,
        #[command(flatten)]
        opts: LaunchArgs,
    },
    /// The supervisor process of a launch, as its keeper starts it (not for direct use).
    #[command(hide = true)]
    Supervise {
        file: PathBuf,
        #[command(flatten)]
        opts: LaunchArgs,
    },
    /// Run a recording's services again on its recorded inputs (deterministically, as fast as
    /// they go) and record them again; `--check` compares the new recording with the old.
    Replay {
        recording: PathBuf,
        /// Report the first message that differs, and exit 1 if any does.
        #[arg(long)]
        check: bool,
        /// Also draw the replay into a Rerun file as the recording did (slower; `harvey export`
        /// draws one afterwards).
        #[arg(long)]
        rrd: bool,
        /// Start whatever binaries the recording's launch file names; without it, only Harvey's
        /// own service binaries (a recording is data from elsewhere).
        #[arg(long)]
        trust_recording: bool,
        /// Run the services as nodes of this one process, one thread, with the same messages
        /// in the same order as over shared memory, and no processes (hundreds of times faster).
        #[arg(long, conflicts_with_all = ["live", "foxglove", "realtime", "zenoh_listen", "zenoh_connect", "host", "ros2_domain"])]
        in_process: bool,
        #[command(flatten)]
        opts: LaunchArgs,
    },
    /// A running domain's topics: `list`, `echo TOPIC`, `hz TOPIC` (as `ros2 topic` does).
    #[command(subcommand)]
    Topic(cmd::topic::TopicCmd),
    /// Prints the iceoryx2 configuration of a bus domain: saved as `config/iceoryx2.toml` where
    /// `iox2` runs, `iox2 service list` sees the domain's services.
    Iox2Config {
        #[arg(long, default_value = harvey_bus::DEFAULT_PREFIX)]
        prefix: String,
    },
    /// Topics, counts, rates, duration and gaps of a recording.
    Info { recording: PathBuf },
    /// Salvage a recording whose writer died: every chunk whose CRC checks, into a valid file.
    Recover {
        recording: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Compare the messages (topic, log time, payload) of two recordings; exit 1 if they differ.
    Diff { a: PathBuf, b: PathBuf },
    /// Draw an MCAP recording into a Rerun file (`rerun run.rrd` opens it).
    Export {
        recording: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Run a mission over seeds x sensor conditions in parallel and tabulate its figure
    /// (DIR/sweep.csv, sweep.md, sweep.png); exit 1 if a run failed, 130 if interrupted.
    Sweep(cmd::sweep::SweepArgs),
    /// Run a mission while seeded random SIGKILLs hit its services; report whether it reached
    /// its goal, how long each service was gone and whether the recording stayed identical
    /// (DIR/chaos.md, chaos.csv); exit 1 if a mission failed.
    Chaos(cmd::chaos::ChaosArgs),
}

fn main() {
    // A closed pipe (`harvey info x.mcap | head`) ends the process quietly, as it does other Unix
    // tools, instead of panicking in `println!`. SAFETY: no other thread runs yet, and SIG_DFL
    // installs no handler.
    unsafe {
        let _ =
            nix::sys::signal::signal(nix::sys::signal::Signal::SIGPIPE, nix::sys::signal::SigHandler::SigDfl);
    }
    let filter = tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into());
    let ansi = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let fmt =
        tracing_subscriber::fmt::layer().with_writer(std::io::stderr).with_target(false).with_ansi(ansi);
    // Nodes run in process (`harvey run|replay --in-process`) send their turns' warnings to rosout,
    // whatever RUST_LOG says, as their processes do (`harvey_runtime::init_logging`).
    let capture =
        harvey_runtime::rosout::CaptureLayer.with_filter(tracing_subscriber::filter::LevelFilter::WARN);
    tracing_subscriber::registry().with(fmt.with_filter(filter)).with(capture).init();
    let cli = Cli::parse();
    let code = match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("harvey: error: {e:#}");
            2
        }
    };
    std::process::exit(code);
}

fn run(cli: Cli) -> anyhow::Result<i32> {
    let cmd = cli.command.unwrap_or(Cmd::Run {
        mission: None,
        in_process: false,
        opts: LaunchArgs {
            run_dir: None,
            prefix: harvey_bus::DEFAULT_PREFIX.into(),
            realtime: false,
            live: None,
            foxglove: None,
            zenoh_listen: Vec::new(),
            zenoh_connect: Vec::new(),
            host: None,
            ros2_domain: None,
        },
    });
    match cmd {
        Cmd::Run { mission, in_process, opts } => cmd::run::run(mission.as_deref(), in_process, &opts),
        Cmd::Launch { file, opts } => cmd::launch::run(&file, &opts),
        Cmd::Supervise { file, opts } => cmd::launch::supervise(&file, &opts),
        Cmd::Replay { recording, check, rrd, trust_recording, in_process, opts } => {
            let how = cmd::replay::How { check, rrd, trust: trust_recording, in_process };
            cmd::replay::run(&recording, how, opts)
        }
        Cmd::Info { recording } => cmd::info::run(&recording),
        Cmd::Topic(t) => cmd::topic::run(&t),
        Cmd::Iox2Config { prefix } => cmd::topic::iox2_config(&prefix),
        Cmd::Diff { a, b } => cmd::diff::run(&a, &b),
        Cmd::Recover { recording, output } => cmd::recover::run(&recording, &output),
        Cmd::Export { recording, output } => cmd::export::run(&recording, &output),
        Cmd::Sweep(args) => cmd::sweep::run(&args),
        Cmd::Chaos(args) => cmd::chaos::run(&args),
    }
}
