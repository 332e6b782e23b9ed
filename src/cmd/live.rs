//! `--live`: where the recorder streams its Rerun drawing, and a viewer started there when the
//! user named none and none answers at Rerun's default address. `--foxglove`: the Foxglove
//! bridge added to a launch as one more service.

use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// The variable through which the recorder learns the viewer's address.
pub const LIVE_ENV: &str = "HARVEY_RERUN_LIVE";
/// Where a Rerun viewer started without arguments listens for SDKs.
const DEFAULT_PORT: u16 = 9876;
/// How long a started viewer may take to listen.
const START_WAIT: Duration = Duration::from_secs(20);

fn answers(addr: &SocketAddr) -> bool {
    TcpStream::connect_timeout(addr, Duration::from_millis(200)).is_ok()
}

/// `rerun` on the PATH, else the one `scripts/test` and `scripts/screenshots` put in `.venv`.
fn rerun_binary() -> Option<PathBuf> {
    let on_path = std::env::var_os("PATH")
        .into_iter()
        .flat_map(|p| std::env::split_paths(&p).collect::<Vec<_>>())
        .map(|d| d.join("rerun"))
        .find(|p| p.is_file());
    on_path.or_else(|| Some(PathBuf::from(".venv/bin/rerun")).filter(|p| p.is_file()))
}

/// The viewer address for `--live [URL]`: `url` as given, or (empty) Rerun's default, with a
/// viewer started there if nothing answers.
pub fn viewer(url: &str) -> anyhow::Result<String> {
    if !url.is_empty() {
        anyhow::ensure!(
            url.starts_with("rerun+http://") || url.starts_with("rerun+https://"),
            "--live {url}: a viewer's address reads rerun+http://HOST:PORT/proxy"
        );
        return Ok(url.to_owned());
    }
    let addr = SocketAddr::from(([127, 0, 0, 1], DEFAULT_PORT));
    let url = format!("rerun+http://127.0.0.1:{DEFAULT_PORT}/proxy");
    if answers(&addr) {
        return Ok(url);
    }
    let Some(rerun) = rerun_binary() else {
        anyhow::bail!(
            "--live: no viewer answers at {addr} and no `rerun` to start (pip install rerun-sdk==0.36.3, \
             or give --live URL)"
        );
    };
    std::process::Command::new(&rerun)
        .args(["--port", &DEFAULT_PORT.to_string()])
        .stdin(std::process::Stdio::null())
        .spawn()
        .map_err(|e| anyhow::anyhow!("--live: starting {}: {e}", rerun.display()))?;
    let until = Instant::now() + START_WAIT;
    while !answers(&addr) {
        anyhow::ensure!(
            Instant::now() < until,
            "--live: {} did not listen at {addr} within {START_WAIT:?}",
            rerun.display()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    Ok(url)
}

/// The Foxglove bridge's service name (its binary: `harvey-foxglove-bridge`, beside `harvey`).
pub const FOXGLOVE_SERVICE: &str = "foxglove-bridge";
/// Where `--foxglove` without an address serves: Foxglove's default.
pub const FOXGLOVE_DEFAULT: &str = "127.0.0.1:8765";

/// Checks `--foxglove ADDR` before anything starts: a HOST:PORT that can be listened on now.
pub fn foxglove_addr(addr: &str) -> anyhow::Result<SocketAddr> {
    let at = addr.to_socket_addrs().ok().and_then(|mut a| a.next()).ok_or_else(|| {
        anyhow::anyhow!("--foxglove {addr}: an address reads HOST:PORT (e.g. {FOXGLOVE_DEFAULT})")
    })?;
    TcpListener::bind(at).map_err(|e| anyhow::anyhow!("--foxglove {addr}: cannot listen there: {e}"))?;
    Ok(at)
}

/// The `[[service]]` `--foxglove ADDR` adds to a launch: the bridge, serving at `addr`, watching
/// the bus without a turn in the clock chain.
pub fn foxglove_service(addr: &str, with_world: bool) -> anyhow::Result<harvey_supervisor::config::Service> {
    let world = if with_world { ", \"--world\", \"${world}\"" } else { "" };
    let text = format!(
        "name = \"{FOXGLOVE_SERVICE}\"\nargs = [\"--listen\", {}{world}]\nclock_party = false\n",
        toml::Value::String(addr.to_owned())
    );
    Ok(toml::from_str(&text)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_foxglove_service_is_the_bridge_off_the_clock_chain() {
        let s = foxglove_service("127.0.0.1:9\"x", false).expect("service");
        assert_eq!((s.name(), s.binary_name().as_str()), ("foxglove-bridge", "harvey-foxglove-bridge"));
        assert_eq!(s.args, ["--listen", "127.0.0.1:9\"x"]);
        let with_world = foxglove_service("127.0.0.1:9", true).expect("service");
        assert_eq!(with_world.args, ["--listen", "127.0.0.1:9", "--world", "${world}"]);
        assert!(!s.clock_party);
        assert!(foxglove_addr("127.0.0.1:0").is_ok());
        let e = foxglove_addr("nowhere").expect_err("no port").to_string();
        assert!(e.contains("HOST:PORT"), "{e}");
    }
}
