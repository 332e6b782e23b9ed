//! harvey: the command line — run the default mission, launch a launch file under the
//! supervisor, and inspect recordings.

mod launch;
mod replay;
mod summary;

use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand};

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
        #[command(flatten)]
        opts: LaunchArgs,
    },
    /// Run a launch file under the supervisor.
    Launch {
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
        #[command(flatten)]
        opts: LaunchArgs,
    },
    /// Topics, counts, rates, duration and gaps of a recording.
    Info { recording: PathBuf },
    /// Salvage every complete chunk of a recording whose writer died into a valid file.
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
}

#[derive(clap::Args)]
struct LaunchArgs {
    /// Output folder (default: recordings/<launch name>).
    #[arg(long)]
    run_dir: Option<PathBuf>,
    /// Bus domain prefix; runs with different prefixes never see each other.
    #[arg(long, default_value = harvey_bus::DEFAULT_PREFIX)]
    prefix: String,
}

const DEFAULT_MISSION: &str = "missions/default.toml";

fn launch_file(file: &Path, args: &LaunchArgs) -> anyhow::Result<(launch::Outcome, PathBuf)> {
    let lf = launch::LaunchFile::load(file)?;
    let run_dir = args.run_dir.clone().unwrap_or_else(|| Path::new("recordings").join(&lf.settings.name));
    let opts = launch::Options { prefix: args.prefix.clone(), run_dir: run_dir.clone() };
    tracing::info!(launch = %lf.settings.name, run_dir = %run_dir.display(), prefix = %opts.prefix, "launching {} services", lf.services.len());
    Ok((launch::run(&lf, &opts)?, run_dir))
}

fn main() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into());
    let ansi = std::io::IsTerminal::is_terminal(&std::io::stderr());
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_target(false)
        .with_ansi(ansi)
        .init();
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
        opts: LaunchArgs { run_dir: None, prefix: harvey_bus::DEFAULT_PREFIX.into() },
    });
    match cmd {
        Cmd::Run { mission, opts } => {
            let file = mission.unwrap_or_else(|| PathBuf::from(DEFAULT_MISSION));
            let (outcome, run_dir) = launch_file(&file, &opts)?;
            let mcap = run_dir.join("run.mcap");
            println!("launch: {outcome:?}");
            if mcap.is_file() {
                let stats = summary::RunStats::read(&mcap)?;
                print!("{}", stats.mission_summary());
                println!(
                    "recording: {} ({} messages on {} topics)",
                    mcap.display(),
                    stats.message_count(),
                    stats.topics.len()
                );
                let rrd = run_dir.join("run.rrd");
                if rrd.is_file() {
                    println!("view it:   rerun {}", rrd.display());
                }
            }
            Ok(outcome.exit_code())
        }
        Cmd::Launch { file, opts } => {
            let (outcome, _) = launch_file(&file, &opts)?;
            println!("launch: {outcome:?}");
            Ok(outcome.exit_code())
        }
        Cmd::Replay { recording, check, rrd, opts } => {
            let run_dir = opts
                .run_dir
                .clone()
                .unwrap_or_else(|| recording.parent().unwrap_or(Path::new(".")).join("replay"));
            let file = replay::prepare(&recording, &run_dir, rrd)?;
            let (outcome, _) = launch_file(&file, &LaunchArgs { run_dir: Some(run_dir.clone()), ..opts })?;
            println!("replay: {outcome:?}");
            let again = run_dir.join("run.mcap");
            println!("recording: {}", again.display());
            if outcome.exit_code() != 0 || !check {
                return Ok(outcome.exit_code());
            }
            let c = harvey_recorder::compare::compare(&recording, &again, &|_| true)?;
            Ok(report_comparison(&c, &recording, &again))
        }
        Cmd::Info { recording } => {
            let stats = summary::RunStats::read(&recording)?;
            print!("{}", stats.info_table());
            if stats.last_status.is_some() {
                print!("{}", stats.mission_summary());
            }
            Ok(0)
        }
        Cmd::Diff { a, b } => {
            let c = harvey_recorder::compare::compare(&a, &b, &|_| true)?;
            Ok(report_comparison(&c, &a, &b))
        }
        Cmd::Recover { recording, output } => {
            let s = harvey_recorder::recover::recover(&recording, &output)?;
            println!(
                "{}: {} messages and {} attachments salvaged{}",
                output.display(),
                s.messages,
                s.attachments,
                s.stopped_at.map(|e| format!(" (the rest was lost: {e})")).unwrap_or_default()
            );
            Ok(0)
        }
        Cmd::Export { recording, output } => {
            // A progress bar for people; logs get only the result line.
            let mut shown = if std::io::IsTerminal::is_terminal(&std::io::stderr()) { 0 } else { u64::MAX };
            let drawn = harvey_recorder::export::export(&recording, &output, |done, total| {
                let pct = (done * 100).checked_div(total).unwrap_or(100);
                if pct >= shown {
                    eprint!(
                        "\rexporting {}: [{:<50}] {pct:>3}%",
                        recording.display(),
                        "#".repeat((pct / 2) as usize)
                    );
                    shown = pct + 2;
                }
            })?;
            if shown != u64::MAX {
                eprintln!();
            }
            println!("{}: {drawn} messages drawn", output.display());
            Ok(0)
        }
    }
}

/// Prints the outcome of a comparison; the exit code is 0 when the recordings agree.
fn report_comparison(c: &harvey_recorder::compare::Comparison, a: &Path, b: &Path) -> i32 {
    match &c.first_difference {
        None => {
            println!("identical: {} messages of {} and {} agree", c.messages, a.display(), b.display());
            0
        }
        Some(d) => {
            println!("DIFFERENT at message {}: {}", d.index, d.detail);
            1
        }
    }
}
