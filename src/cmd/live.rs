//! `--live`: where the recorder streams its Rerun drawing, and a viewer started there when the
//! user named none and none answers at Rerun's default address.

use std::net::{SocketAddr, TcpStream};
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
