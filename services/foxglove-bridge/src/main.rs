//! harvey-foxglove-bridge: serves every topic of a running domain to Foxglove, live, over the
//! Foxglove WebSocket protocol (`harvey run --foxglove`; `docs/foxglove.md`). Each Harvey topic
//! is one channel (`/odometry`) of `cdr` messages with the topic's `ros2msg` schema, the bytes
//! being those the recorder writes to `run.mcap`, each logged at its own stamp. It watches the
//! bus as an observer: in deterministic mode it takes no turn in the clock chain and slows
//! nobody (its queues overwrite when a client is slow). SIGINT or SIGTERM stops it.

use std::net::{SocketAddr, ToSocketAddrs};
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use foxglove::WebSocketServer;
use foxglove::websocket::Capability;
use harvey_bus::{Bus, Waiter, Wake};

mod bridge;
mod derive;

/// Where the bridge listens unless told otherwise: Foxglove's own default.
const DEFAULT_LISTEN: &str = "127.0.0.1:8765";
/// How often the counts are logged while clients are connected.
const REPORT_EVERY: Duration = Duration::from_secs(10);

#[derive(Parser)]
#[command(about = "Serve every topic live to Foxglove (WebSocket protocol)")]
struct Args {
    /// Address to listen on, HOST:PORT (port 0: any free port, logged once listening).
    #[arg(long, default_value = DEFAULT_LISTEN)]
    listen: String,
    /// Messages queued per client before the oldest are dropped (a slow client loses messages,
    /// never slows the robot).
    #[arg(long, default_value_t = 1024)]
    backlog: usize,
    /// The run's world file: the map's markers and the camera's height in the derived topics.
    #[arg(long)]
    world: Option<std::path::PathBuf>,
}

/// `HOST:PORT` resolved to the address to bind.
fn listen_addr(text: &str) -> anyhow::Result<SocketAddr> {
    text.to_socket_addrs()
        .with_context(|| format!("--listen {text}: not HOST:PORT"))?
        .next()
        .ok_or_else(|| anyhow::anyhow!("--listen {text}: names no address"))
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let addr = listen_addr(&args.listen)?;
    let world = match &args.world {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
            Some(harvey_world::load_str(&text, &path.display().to_string())?)
        }
        None => None,
    };
    let bus = Bus::join("foxglove-bridge")?;
    let taps = harvey_runtime::taps::open_all(&bus)?;
    // Channels are advertised to every client that connects from now on.
    let latched = std::sync::Arc::new(derive::Latched::default());
    let mut bridge = bridge::Bridge::new(&taps, derive::hook(world.as_ref()), latched.clone())?;
    let server = WebSocketServer::new()
        .listener(latched)
        .name(format!("harvey ({})", bus.prefix()))
        .bind(addr.ip().to_string(), addr.port())
        .capabilities([Capability::Time])
        .message_backlog_size(args.backlog)
        .start_blocking()
        .map_err(|e| anyhow::anyhow!("cannot serve Foxglove at {addr}: {e}"))?;
    let url = format!("ws://{}:{}", addr.ip(), server.port());
    // `notify_ready` removes its variable: the server's threads now run, but they read no
    // environment, and Rust's own environment access is locked.
    harvey_runtime::notify_ready()?;
    tracing::info!(url, topics = taps.len(), derived = ?bridge.derived_topics(), "serving Foxglove: open a Foxglove WebSocket connection to {url}");

    let waiter = Waiter::new()?;
    let _attached =
        taps.iter().map(|t| waiter.attach(t.waitable())).collect::<Result<Vec<_>, harvey_bus::BusError>>()?;
    let (mut time_sent, mut reported) = (0u64, Instant::now());
    loop {
        match waiter.wait(Some(REPORT_EVERY))? {
            Wake::Shutdown => break,
            Wake::Ready | Wake::Timeout => {}
        }
        for (i, t) in taps.iter().enumerate() {
            bridge.forward(i, t.as_ref())?;
        }
        if bridge.newest_ns > time_sent {
            time_sent = bridge.newest_ns;
            server.broadcast_time(time_sent);
        }
        if reported.elapsed() >= REPORT_EVERY && server.client_count() > 0 {
            reported = Instant::now();
            let sent: u64 = bridge.counts().iter().map(|c| c.sent).sum();
            tracing::info!(clients = server.client_count(), sent, "forwarding");
        }
    }
    drop(_attached);
    server.stop().wait_blocking();
    let taken: u64 = bridge.counts().iter().map(|c| c.taken).sum();
    let sent: u64 = bridge.counts().iter().map(|c| c.sent).sum();
    tracing::info!(taken, sent, "Foxglove bridge stopped");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn listen_addresses_resolve_or_say_why_not() {
        assert_eq!(listen_addr(DEFAULT_LISTEN).expect("default"), SocketAddr::from(([127, 0, 0, 1], 8765)));
        assert_eq!(listen_addr("127.0.0.1:0").expect("any port").port(), 0);
        assert!(listen_addr("localhost:9000").expect("a name").ip().is_loopback());
        let e = listen_addr("8765").expect_err("no host").to_string();
        assert!(e.contains("not HOST:PORT"), "{e}");
    }
}
