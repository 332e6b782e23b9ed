//! Exporting: the chosen topics taken from the local bus (`harvey_runtime::taps`) and put on
//! Zenoh, one reliable, blocking publisher per topic (a slow link slows the bridge, it never
//! drops), each sample the recorder's CDR with the [`Meta`] attachment, and a liveliness token
//! per topic so that the other hosts see what this one exports.

use harvey_runtime::taps::Tap;
use zenoh::Wait;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Publisher;
use zenoh::qos::CongestionControl;

use crate::wire::{self, Meta};

/// One exported topic.
struct Out {
    publisher: Publisher<'static>,
    fingerprint: u32,
    _token: LivelinessToken,
    sent: u64,
}

/// The exported topics of a bridge: a publisher for each of the taps it was made for.
pub struct Exporter {
    topics: Vec<&'static str>,
    outs: Vec<Out>,
    /// Messages stamped after the tick whose turn took them (deterministic mode), not put:
    /// the recorder leaves them out too.
    pub left_out: u64,
}

impl Exporter {
    /// Declares a (reliable: Zenoh's default) publisher and a liveliness token for each tap.
    pub fn new(
        session: &zenoh::Session,
        namespace: &str,
        host: &str,
        taps: &[Box<dyn Tap>],
    ) -> anyhow::Result<Self> {
        let mut outs = Vec::with_capacity(taps.len());
        for t in taps {
            let key = wire::data_key(namespace, t.topic());
            let publisher = session
                .declare_publisher(key.clone())
                .congestion_control(CongestionControl::Block)
                .wait()
                .map_err(|e| anyhow::anyhow!("cannot publish {key} on Zenoh: {e}"))?;
            let live = wire::live_key(namespace, host, t.topic());
            let token = session
                .liveliness()
                .declare_token(live.clone())
                .wait()
                .map_err(|e| anyhow::anyhow!("cannot declare {live} on Zenoh: {e}"))?;
            outs.push(Out { publisher, fingerprint: wire::fingerprint(t.def()), _token: token, sent: 0 });
        }
        Ok(Self { topics: taps.iter().map(|t| t.topic()).collect(), outs, left_out: 0 })
    }

    /// Puts every message queued on `taps` (those it was made for) stamped at most `until_ns`,
    /// in their order, as the recorder records them; returns how many were taken.
    pub fn forward(&mut self, taps: &[Box<dyn Tap>], until_ns: u64) -> anyhow::Result<u64> {
        let (mut total, mut left_out) = (0, 0);
        for (tap, out) in taps.iter().zip(self.outs.iter_mut()) {
            let mut failed = None;
            let n = tap.take_owned(&|_| false, &mut |seq, stamp_ns, cdr| {
                if failed.is_some() {
                    return;
                }
                if stamp_ns > until_ns {
                    left_out += 1;
                    return;
                }
                let meta = Meta { seq, stamp_ns, fingerprint: out.fingerprint };
                // The CDR buffer goes to Zenoh as it is: no copy on the way.
                match out.publisher.put(cdr).attachment(meta.encode().to_vec()).wait() {
                    Ok(()) => out.sent += 1,
                    Err(e) => failed = Some(anyhow::anyhow!("putting {} on Zenoh: {e}", tap.topic())),
                }
            })?;
            if let Some(e) = failed {
                return Err(e);
            }
            total += n as u64;
        }
        self.left_out += left_out;
        Ok(total)
    }

    /// Samples put so far, per topic.
    pub fn counts(&self) -> impl Iterator<Item = (&'static str, u64)> + '_ {
        self.topics.iter().zip(&self.outs).map(|(t, o)| (*t, o.sent))
    }
}
