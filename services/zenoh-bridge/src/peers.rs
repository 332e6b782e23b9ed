//! The other hosts as the liveliness tokens show them: before an importing bridge says it is
//! ready, every topic it imports must be exported by some host, or it gives up naming the
//! topics nobody exports (a host that never joined, a wrong endpoint) instead of hanging.

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use zenoh::Wait;

use crate::wire;

/// The keys of the liveliness tokens live now that match `key`.
pub fn live_keys(session: &zenoh::Session, key: &str) -> anyhow::Result<Vec<String>> {
    let replies = session
        .liveliness()
        .get(key.to_owned())
        .timeout(Duration::from_millis(500))
        .wait()
        .map_err(|e| anyhow::anyhow!("asking Zenoh for {key}: {e}"))?;
    let mut out = Vec::new();
    while let Ok(reply) = replies.recv() {
        if let Ok(sample) = reply.result() {
            out.push(sample.key_expr().as_str().to_owned());
        }
    }
    Ok(out)
}

/// `(layout, host, topic)` of every liveliness token live in `namespace` now.
fn live_tokens(session: &zenoh::Session, namespace: &str) -> anyhow::Result<Vec<(String, String, String)>> {
    let keys = live_keys(session, &wire::live_all(namespace))?;
    Ok(keys
        .iter()
        .filter_map(|k| wire::parse_live_key(namespace, k))
        .map(|(layout, host, topic)| (layout.to_owned(), host.to_owned(), topic.to_owned()))
        .collect())
}

/// Waits until a host of this layout exports each of `topics`, at most `wait`.
pub fn await_exporters(
    session: &zenoh::Session,
    namespace: &str,
    topics: &[String],
    wait: Duration,
) -> anyhow::Result<()> {
    let start = Instant::now();
    let layout = wire::LAYOUT.to_string();
    loop {
        let tokens = live_tokens(session, namespace)?;
        let other: BTreeSet<String> =
            tokens.iter().filter(|(l, ..)| *l != layout).map(|(l, h, _)| format!("{h} (v{l})")).collect();
        if !other.is_empty() {
            anyhow::bail!(
                "hosts {other:?} speak another key layout than this Harvey's v{layout}: another Harvey version"
            );
        }
        let missing: Vec<&String> =
            topics.iter().filter(|t| !tokens.iter().any(|(_, _, x)| x == *t)).collect();
        if missing.is_empty() {
            for (_, host, topic) in tokens.iter().filter(|(.., t)| topics.contains(t)) {
                tracing::info!(topic, host, "importing");
            }
            return Ok(());
        }
        if start.elapsed() >= wait {
            anyhow::bail!(
                "no host exports {missing:?} after {} s: is the other host's bridge running, with --zenoh-connect or --zenoh-listen pointing here?",
                wait.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The liveliness token of a bridge whose chain has started.
pub fn ready_key(namespace: &str, host: &str) -> String {
    format!("{namespace}/@chain/v{}/ready/{host}", wire::LAYOUT)
}

/// Waits (at most `wait`) until the other host's bridge has started its chain, or names it.
pub fn await_peer(
    session: &zenoh::Session,
    namespace: &str,
    peer: &str,
    wait: Duration,
) -> anyhow::Result<()> {
    let key = ready_key(namespace, peer);
    let start = Instant::now();
    loop {
        if !live_keys(session, &key)?.is_empty() {
            return Ok(());
        }
        anyhow::ensure!(
            start.elapsed() < wait,
            "host {peer} never joined within {} s: start its share (`harvey launch FILE --host {peer}` with \
             --zenoh-connect or --zenoh-listen pointing here)",
            wait.as_secs()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Says this host's bridge is up (a liveliness token the other host's bridge waits for).
pub fn declare_ready(
    session: &zenoh::Session,
    namespace: &str,
    host: &str,
) -> anyhow::Result<zenoh::liveliness::LivelinessToken> {
    session
        .liveliness()
        .declare_token(ready_key(namespace, host))
        .wait()
        .map_err(|e| anyhow::anyhow!("declaring this host ready on Zenoh: {e}"))
}
