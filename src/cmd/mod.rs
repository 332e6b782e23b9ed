//! The CLI's commands, one file each, and what several of them share: launching a launch file
//! under the supervisor and reporting a comparison of two recordings.

pub mod chaos;
pub mod diff;
pub mod export;
mod hosts;
pub mod info;
mod inproc;
pub mod launch;
mod live;
pub mod recover;
pub mod replay;
mod replay_launch;
mod rrd_arg;
pub mod run;
pub mod sweep;
pub mod topic;
mod zenoh;

use std::path::{Path, PathBuf};

/// Where a launch writes and which bus domain it uses.
#[derive(clap::Args)]
pub struct LaunchArgs {
    /// Output folder (default: recordings/<launch name>).
    #[arg(long)]
    pub run_dir: Option<PathBuf>,
    /// Bus domain prefix; runs with different prefixes never see each other.
    #[arg(long, default_value = harvey_bus::DEFAULT_PREFIX)]
    pub prefix: String,
    /// Pace the launch by the wall clock (`clock = "realtime"`), as a real robot is, whatever
    /// its file says: to watch a run as it happens. Not deterministic.
    #[arg(long)]
    pub realtime: bool,
    /// Also stream the recorder's Rerun drawing live to a viewer: at URL
    /// (`rerun+http://HOST:PORT/proxy`), or without one to the viewer at Rerun's default address,
    /// started (`rerun` on the PATH or in `.venv`) if none answers there. The MCAP is unchanged.
    #[arg(long, num_args = 0..=1, default_missing_value = "", value_name = "URL")]
    pub live: Option<String>,
    /// Also serve every topic live to Foxglove (`docs/foxglove.md`): the Foxglove bridge runs as
    /// one more service, a Foxglove WebSocket server at ADDR (HOST:PORT; without one,
    /// 127.0.0.1:8765). Give it as `--foxglove=ADDR` before a mission's path.
    #[arg(long, num_args = 0..=1, default_missing_value = live::FOXGLOVE_DEFAULT, value_name = "ADDR")]
    pub foxglove: Option<String>,
    /// Also export every topic on Zenoh (`docs/zenoh.md`): the Zenoh bridge runs as one more
    /// service, listening at ENDPOINT (`tcp/HOST:PORT`; repeatable) for peers on other hosts.
    #[arg(long, value_name = "ENDPOINT")]
    pub zenoh_listen: Vec<String>,
    /// Like `--zenoh-listen`, but the bridge connects to a peer listening at ENDPOINT.
    #[arg(long, value_name = "ENDPOINT")]
    pub zenoh_connect: Vec<String>,
    /// Run only this host's share of a launch split over hosts (`host = "NAME"` on its
    /// services; unplaced ones are `main`'s), joined to the other host's over Zenoh at
    /// `--zenoh-listen`/`--zenoh-connect` (`docs/zenoh.md`).
    #[arg(long, value_name = "NAME")]
    pub host: Option<String>,
    /// With `--zenoh-listen`/`--zenoh-connect`: also publish every topic as ROS 2 Jazzy's
    /// `rmw_zenoh_cpp` does in this `ROS_DOMAIN_ID`, for `ros2 topic list/echo` (`docs/zenoh.md`).
    #[arg(long, value_name = "DOMAIN_ID", value_parser = clap::value_parser!(u32).range(0..=232))]
    pub ros2_domain: Option<u32>,
}

impl LaunchArgs {
    /// Whether the launch gets a Zenoh bridge.
    pub fn zenoh(&self) -> bool {
        !self.zenoh_listen.is_empty() || !self.zenoh_connect.is_empty()
    }
}

/// Where launch file `lf` runs, given `args`.
fn launch_options(lf: &harvey_supervisor::LaunchFile, args: &LaunchArgs) -> harvey_supervisor::Options {
    let run_dir = args.run_dir.clone().unwrap_or_else(|| Path::new("recordings").join(&lf.settings.name));
    harvey_supervisor::Options { prefix: args.prefix.clone(), run_dir }
}

/// Runs launch file `file` under the keeper, which runs the supervisor (`harvey supervise`) as
/// its child and a new one if that dies; returns how the launch ended and its run folder. A
/// supervisor that failed has said why: this process exits with its code.
fn launch_file(file: &Path, args: &LaunchArgs) -> anyhow::Result<(harvey_supervisor::Outcome, PathBuf)> {
    let lf = harvey_supervisor::LaunchFile::load(file)?;
    let opts = launch_options(&lf, args);
    harvey_bus::validate_prefix(&opts.prefix)?;
    if let Some(url) = &args.live {
        let url = live::viewer(url)?;
        println!("live: drawing to the Rerun viewer at {url}");
        // SAFETY: the CLI is single-threaded here, before it starts any process or thread; the
        // recorder, a child of this keeper process, reads the variable.
        unsafe { std::env::set_var(live::LIVE_ENV, &url) };
    }
    if let Some(addr) = &args.foxglove {
        let at = live::foxglove_addr(addr)?;
        let url =
            if at.port() == 0 { format!("ws://{}:<a free port>", at.ip()) } else { format!("ws://{at}") };
        println!("foxglove: serving at {url} (Foxglove: Open connection, Foxglove WebSocket)");
    }
    if let Some(host) = &args.host {
        // Checked here too, so that a bad placement is said before anything starts.
        hosts::place(&mut lf.clone(), host, &args.zenoh_listen, &args.zenoh_connect)?;
        zenoh::check_endpoints(&args.zenoh_listen, &args.zenoh_connect)?;
        println!(
            "zenoh: host {host}'s share (listen {:?}, connect {:?})",
            args.zenoh_listen, args.zenoh_connect
        );
    } else if args.zenoh() || args.ros2_domain.is_some() {
        anyhow::ensure!(args.zenoh(), "--ros2-domain: give --zenoh-listen or --zenoh-connect too");
        zenoh::check_endpoints(&args.zenoh_listen, &args.zenoh_connect)?;
        println!(
            "zenoh: every topic exported (listen {:?}, connect {:?})",
            args.zenoh_listen, args.zenoh_connect
        );
    }
    tracing::info!(launch = %lf.settings.name, run_dir = %opts.run_dir.display(), prefix = %opts.prefix, "launching {} services", lf.services.len());
    let exe = std::env::current_exe()?;
    let make = || {
        let mut cmd = std::process::Command::new(&exe);
        cmd.arg("supervise").arg(file).arg("--run-dir").arg(&opts.run_dir).args(["--prefix", &opts.prefix]);
        if args.realtime {
            cmd.arg("--realtime");
        }
        if let Some(addr) = &args.foxglove {
            cmd.arg(format!("--foxglove={addr}"));
        }
        for e in &args.zenoh_listen {
            cmd.args(["--zenoh-listen", e]);
        }
        for e in &args.zenoh_connect {
            cmd.args(["--zenoh-connect", e]);
        }
        if let Some(host) = &args.host {
            cmd.args(["--host", host]);
        }
        if let Some(d) = args.ros2_domain {
            cmd.args(["--ros2-domain", &d.to_string()]);
        }
        cmd
    };
    let grace = std::time::Duration::from_millis(lf.settings.grace_period_ms);
    match harvey_supervisor::keep(&make, grace)? {
        harvey_supervisor::Kept::Outcome(o) => Ok((o, opts.run_dir)),
        harvey_supervisor::Kept::Failed(code) => std::process::exit(code),
    }
}

/// Prints the outcome of a comparison; the exit code is 0 when the recordings agree.
fn report_comparison(c: &harvey_recording::compare::Comparison, a: &Path, b: &Path) -> i32 {
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
