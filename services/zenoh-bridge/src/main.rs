//! harvey-zenoh-bridge: carries chosen topics between this host's bus and Zenoh
//! (`docs/zenoh.md`): exported topics are taken off the bus and put on Zenoh in the recorder's
//! CDR, imported ones are taken off Zenoh and published on the bus. A peer on exactly the
//! endpoints given (multicast off). In a deterministic launch an exporting bridge is a clock
//! party, so every tick's messages leave before the next tick starts; otherwise it runs as an
//! observer, woken by the bus and by Zenoh. SIGINT or SIGTERM stops it.

use std::time::{Duration, Instant};

use clap::Parser;
use harvey_bus::{Bus, FdSource, Pace, Step, Waitable, Waiter};
use harvey_msgs::topics;
use zenoh::Wait;

mod bundle;
mod chain;
mod export;
mod import;
mod keep;
mod live;
mod mailbox;
mod peers;
mod ros2;
mod segment;
mod session;
mod sinks;
mod wire;

/// How often the counts are logged.
const REPORT_EVERY: Duration = Duration::from_secs(10);

#[derive(Parser)]
#[command(about = "Carry topics between this host's bus and Zenoh")]
struct Args {
    /// Listen for Zenoh peers here (`tcp/HOST:PORT`; repeatable).
    #[arg(long = "zenoh-listen")]
    listen: Vec<String>,
    /// Connect to a Zenoh peer here (`tcp/HOST:PORT`; repeatable).
    #[arg(long = "zenoh-connect")]
    connect: Vec<String>,
    /// This host's name, in the liveliness tokens the other hosts see.
    #[arg(long, default_value = "local")]
    host: String,
    /// The first part of every key: runs in different namespaces never see each other.
    #[arg(long, default_value = "harvey")]
    namespace: String,
    /// Topics to put on Zenoh, comma-separated, or `all`.
    #[arg(long, value_delimiter = ',')]
    export: Vec<String>,
    /// Topics to take from Zenoh and publish here, comma-separated.
    #[arg(long, value_delimiter = ',')]
    import: Vec<String>,
    /// The largest camera frame taken from Zenoh (default: 1920x1080 rgb8).
    #[arg(long, default_value_t = 1920 * 1080 * 3)]
    max_frame_bytes: usize,
    /// How long to wait for a host exporting each imported topic (or for the other host of a
    /// chain) before giving up, naming them.
    #[arg(long, default_value_t = 30)]
    wait_s: u64,
    /// Carry every topic to and from `--peer-host` (a launch split over two hosts, `harvey
    /// launch FILE --host NAME`): `stand-in` on the main host (in a deterministic launch a party
    /// in place of the other host's services), `segment` on the other host (its clock master).
    #[arg(long, value_enum, requires = "peer_host", conflicts_with_all = ["export", "import"])]
    chain: Option<Role>,
    /// Also put every exported topic as ROS 2 (Jazzy, `rmw_zenoh_cpp`) does in this
    /// `ROS_DOMAIN_ID`: keys with RIHS01 type hashes, rmw_zenoh's attachment and liveliness
    /// tokens, so that `ros2 topic list/echo` there sees them (`docs/zenoh.md`).
    #[arg(long, value_name = "DOMAIN_ID", value_parser = clap::value_parser!(u32).range(0..=232))]
    ros2_domain: Option<u32>,
    /// The other host of the chain.
    #[arg(long)]
    peer_host: Option<String>,
}

/// `--chain`'s values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Role {
    StandIn,
    Segment,
}

/// `--export`'s topics: `all`, or names each checked.
fn exported(args: &Args) -> anyhow::Result<Vec<String>> {
    if args.export.iter().any(|t| t == "all") {
        return Ok(topics::ALL
            .iter()
            .filter(|t| !args.import.iter().any(|i| i == *t))
            .map(|t| (*t).to_owned())
            .collect());
    }
    for t in args.export.iter().chain(&args.import) {
        anyhow::ensure!(
            topics::ALL.contains(&t.as_str()),
            "`{t}` is no Harvey topic (topics: {:?})",
            topics::ALL
        );
        anyhow::ensure!(
            !(args.export.contains(t) && args.import.contains(t)),
            "`{t}` is both exported and imported: a topic has one owner"
        );
    }
    Ok(args.export.clone())
}

/// A name that goes into a key expression: letters, digits, `-` and `_`.
fn check_name(flag: &str, name: &str) -> anyhow::Result<()> {
    anyhow::ensure!(
        harvey_bus::is_plain_name(name),
        "{flag} `{name}`: use letters, digits, `-` and `_` only"
    );
    Ok(())
}

/// Zenoh's own log, unless `RUST_LOG` says otherwise: its warnings, without the one it gives
/// every peer that runs without gossip, as the bridge always does (`session.rs`).
const ZENOH_LOG: &str = "info,zenoh=warn,zenoh::net::routing::hat=error";

fn main() -> anyhow::Result<()> {
    if std::env::var_os("RUST_LOG").is_none() {
        // SAFETY: first thing in main, before any thread exists.
        unsafe { std::env::set_var("RUST_LOG", ZENOH_LOG) };
    }
    harvey_runtime::init_logging();
    let args = Args::parse();
    check_name("--host", &args.host)?;
    check_name("--namespace", &args.namespace)?;
    if let Some(peer) = &args.peer_host {
        check_name("--peer-host", peer)?;
    }
    let export = exported(&args)?;
    anyhow::ensure!(
        args.chain.is_some() || !export.is_empty() || !args.import.is_empty(),
        "nothing to carry: give --export, --import or --chain"
    );
    let ends = session::Endpoints { listen: args.listen.clone(), connect: args.connect.clone() };
    let session = session::open(&ends)?;
    let bus = Bus::join("zenoh-bridge")?;
    let pace = Pace::from_env(&bus)?;
    let mut sinks = sinks::Sinks::new(args.max_frame_bytes);
    match (args.chain, &args.peer_host) {
        (Some(role), Some(peer)) => run_chain(&args, role, peer, &session, &bus, &pace, &mut sinks)?,
        _ => run_topics(&args, &export, &session, &bus, &pace, &mut sinks)?,
    }
    session.close().wait().map_err(|e| anyhow::anyhow!("closing the Zenoh session: {e}"))?;
    Ok(())
}

/// `--chain`: every topic between this host and the other, tick by tick in a deterministic
/// launch, as it comes in real time.
fn run_chain(
    args: &Args,
    role: Role,
    peer: &str,
    session: &zenoh::Session,
    bus: &Bus,
    pace: &Pace,
    sinks: &mut sinks::Sinks,
) -> anyhow::Result<()> {
    let taps = harvey_runtime::taps::open_all(bus)?;
    let wait = Duration::from_secs(args.wait_s);
    let mut chain = chain::Chain::new(session, &args.namespace, (&args.host, peer, wait), bus, &taps, sinks)?;
    let lockstep = pace.lockstep();
    tracing::info!(host = args.host, peer, ?role, lockstep = lockstep.is_some(), listen = ?args.listen, connect = ?args.connect, "carrying every topic to the other host over Zenoh");
    let Some(lockstep) = lockstep else {
        let _ready = peers::declare_ready(session, &args.namespace, &args.host)?;
        if role == Role::StandIn {
            peers::await_peer(session, &args.namespace, peer, wait)?;
        }
        harvey_runtime::notify_ready()?;
        return chain.run_live(role == Role::StandIn);
    };
    if role == Role::Segment {
        harvey_runtime::notify_ready()?;
        return chain.run_segment(session, &args.namespace, &args.host, lockstep);
    }
    peers::await_peer(session, &args.namespace, peer, wait)?;
    let waiter = Waiter::new()?;
    let _attached = pace.attach(&waiter, &[])?;
    let turn_waiter = Waiter::new()?;
    let bell = FdSource::new(chain.bell())?;
    let reoffers = chain.reoffer_bell();
    let _bell = (turn_waiter.attach(&bell)?, turn_waiter.attach(&*reoffers)?);
    harvey_runtime::notify_ready()?;
    // A restarted bridge may be granted a tick twice (the supervisor's grant and its
    // predecessor's progress, if that came after this process subscribed): the turn is taken once.
    let mut last_turn = None;
    loop {
        match pace.next(&waiter, Some(REPORT_EVERY))? {
            Step::Stop => break,
            Step::Go(Some(tick)) if last_turn == Some(tick) => continue,
            Step::Go(Some(tick)) => {
                last_turn = Some(tick);
                if !chain.stand_in_turn(&turn_waiter, tick)? {
                    break;
                }
            }
            Step::Go(None) | Step::Idle => {}
        }
        pace.done()?;
    }
    chain.end()
}

/// `--export` and `--import`: topics one by one, each on its own key.
fn run_topics(
    args: &Args,
    export: &[String],
    session: &zenoh::Session,
    bus: &Bus,
    pace: &Pace,
    sinks: &mut sinks::Sinks,
) -> anyhow::Result<()> {
    anyhow::ensure!(
        pace.lockstep().is_none() || args.import.is_empty(),
        "importing topics one by one into a deterministic launch would let them in outside the \
         chain's turns: split a deterministic launch with `harvey launch FILE --host NAME` (--chain), \
         run it with --realtime, or export only"
    );
    let taps = harvey_runtime::taps::open(bus, |t| export.iter().any(|e| e == t))?;
    let mut exporter = export::Exporter::new(session, &args.namespace, &args.host, &taps, args.ros2_domain)?;
    let mut importer = import::Importer::new(session, bus, sinks, &args.namespace, &args.import)?;
    if !args.import.is_empty() {
        peers::await_exporters(session, &args.namespace, &args.import, Duration::from_secs(args.wait_s))?;
    }
    let lockstep = pace.lockstep().is_some();
    let waiter = Waiter::new()?;
    let bell = FdSource::new(importer.bell())?;
    let mut wakers: Vec<&dyn Waitable> = taps.iter().map(|t| t.waitable()).collect();
    wakers.push(&bell);
    let _attached = pace.attach(&waiter, &wakers)?;
    harvey_runtime::notify_ready()?;
    tracing::info!(host = args.host, listen = ?args.listen, connect = ?args.connect, exported = export.len(), imported = ?args.import, lockstep, "bridging to Zenoh");

    let mut reported = Instant::now();
    loop {
        let step = pace.next(&waiter, Some(REPORT_EVERY))?;
        if step == Step::Stop {
            break;
        }
        // In deterministic mode an idle wake-up takes nothing: the tick may still be under way.
        let until_ns = match step {
            Step::Go(Some(tick)) => tick,
            Step::Idle if lockstep => {
                pace.done()?;
                continue;
            }
            _ => u64::MAX,
        };
        exporter.forward(&taps, until_ns)?;
        importer.drain(bus, sinks)?;
        pace.done()?;
        if reported.elapsed() >= REPORT_EVERY {
            reported = Instant::now();
            let sent: u64 = exporter.counts().map(|(_, n)| n).sum();
            let published: u64 = importer.counts().values().map(|c| c.published).sum();
            tracing::info!(sent, published, "bridging");
        }
    }
    drop(_attached);
    // In real time, what is still queued goes out before the session closes (in deterministic
    // mode it belongs to no tick the recorder records).
    if !lockstep {
        exporter.forward(&taps, u64::MAX)?;
    }
    let sent: Vec<(&str, u64)> = exporter.counts().collect();
    tracing::info!(?sent, left_out = exporter.left_out, imported = ?importer.counts(), "Zenoh bridge stopped");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(line: &str) -> Args {
        Args::parse_from(std::iter::once("harvey-zenoh-bridge").chain(line.split_whitespace()))
    }

    #[test]
    fn exports_and_imports_are_topics_each_with_one_owner() {
        let all = exported(&args("--export all --import ums/map")).expect("all");
        assert_eq!(all.len(), topics::ALL.len() - 1);
        assert!(!all.iter().any(|t| t == "ums/map"));
        let some = exported(&args("--export odometry,camera/frame")).expect("two");
        assert_eq!(some, ["odometry", "camera/frame"]);
        let e = exported(&args("--export odometry --import odometry")).expect_err("both").to_string();
        assert!(e.contains("`odometry` is both exported and imported"), "{e}");
        let e = exported(&args("--import odometri")).expect_err("unknown").to_string();
        assert!(e.contains("`odometri` is no Harvey topic"), "{e}");
        assert!(check_name("--host", "robot-1").is_ok());
        assert!(check_name("--host", "a/b").is_err());
        assert!(check_name("--namespace", "").is_err());
    }
}
