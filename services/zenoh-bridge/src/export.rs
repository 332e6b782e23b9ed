//! Exporting: the chosen topics taken from the local bus (`harvey_runtime::taps`) and put on
//! Zenoh, one reliable, blocking publisher per topic (a slow link slows the bridge, it never
//! drops), each sample the recorder's CDR with the [`Meta`] attachment, and a liveliness token
//! per topic so that the other hosts see what this one exports. With a ROS 2 domain it also
//! puts each sample as rmw_zenoh does (`crate::ros2`: key with the RIHS01 type hash, its
//! attachment, the node's and each publisher's liveliness tokens), so that ROS 2 Jazzy nodes
//! on `rmw_zenoh_cpp` see the topics (`/camera/frame` as `sensor_msgs/msg/Image`).

use harvey_runtime::taps::Tap;
use zenoh::Wait;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Publisher;
use zenoh::qos::CongestionControl;

use crate::ros2;
use crate::wire::{self, Meta};

/// One exported topic.
struct Out {
    publisher: Publisher<'static>,
    fingerprint: u32,
    _token: LivelinessToken,
    sent: u64,
    ros2: Option<Ros2Out>,
}

/// A topic as rmw_zenoh publishes it.
struct Ros2Out {
    publisher: Publisher<'static>,
    _token: LivelinessToken,
    gid: [u8; ros2::GID_LEN],
    /// rmw_zenoh numbers a publisher's samples from 1.
    seq: i64,
}

/// What ROS 2 sees of the bridge: one node, `harvey_<host>`, publishing every exported topic.
fn ros2_out(
    session: &zenoh::Session,
    node: &ros2::Node<'_>,
    entity_id: u64,
    tap: &dyn Tap,
) -> anyhow::Result<Ros2Out> {
    let key = ros2::data_key(node.domain_id, tap.topic(), tap.def())?;
    let publisher = session
        .declare_publisher(key.clone())
        .congestion_control(CongestionControl::Block)
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot publish {key} on Zenoh: {e}"))?;
    let (type_name, hash) = (ros2::dds_type_name(tap.def())?, ros2::rihs01(tap.def())?);
    let live = ros2::publisher_token(node, entity_id, tap.topic(), &type_name, &hash, &ros2::Qos::default())?;
    let token = session
        .liveliness()
        .declare_token(live.clone())
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot declare {live} on Zenoh: {e}"))?;
    // rmw_zenoh hashes the token (XXH3-128); any 16 bytes do, as receivers only report them.
    let digest = <sha2::Sha256 as sha2::Digest>::digest(live.as_bytes());
    let mut gid = [0u8; ros2::GID_LEN];
    gid.copy_from_slice(&digest[..ros2::GID_LEN]);
    Ok(Ros2Out { publisher, _token: token, gid, seq: 0 })
}

/// The exported topics of a bridge: a publisher for each of the taps it was made for.
pub struct Exporter {
    topics: Vec<&'static str>,
    outs: Vec<Out>,
    _node_token: Option<LivelinessToken>,
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
        ros2_domain: Option<u32>,
    ) -> anyhow::Result<Self> {
        let zid = session.zid().to_string();
        let name = format!("harvey_{}", host.replace('-', "_"));
        let node = ros2::Node {
            domain_id: ros2_domain.unwrap_or(0),
            zid: &zid,
            node_id: 0,
            enclave: "/",
            namespace: "/",
            name: &name,
        };
        let node_token = match ros2_domain {
            Some(_) => {
                let key = ros2::node_token(&node)?;
                Some(
                    session
                        .liveliness()
                        .declare_token(key.clone())
                        .wait()
                        .map_err(|e| anyhow::anyhow!("cannot declare {key} on Zenoh: {e}"))?,
                )
            }
            None => None,
        };
        let mut outs = Vec::with_capacity(taps.len());
        for (i, t) in taps.iter().enumerate() {
            let ros2 = ros2_domain.map(|_| ros2_out(session, &node, i as u64 + 1, t.as_ref())).transpose()?;
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
            outs.push(Out {
                publisher,
                fingerprint: wire::fingerprint(t.def()),
                _token: token,
                sent: 0,
                ros2,
            });
        }
        Ok(Self {
            topics: taps.iter().map(|t| t.topic()).collect(),
            outs,
            _node_token: node_token,
            left_out: 0,
        })
    }

    /// Puts every message queued on `taps` (those it was made for) stamped at most `until_ns`,
    /// in their order, as the recorder records them; returns how many were taken.
    pub fn forward(&mut self, taps: &[Box<dyn Tap>], until_ns: u64) -> anyhow::Result<u64> {
        let (mut total, mut left_out) = (0, 0);
        for (tap, out) in taps.iter().zip(self.outs.iter_mut()) {
            let mut failed = None;
            let n = tap.take_owned(&|_| false, &mut |_, seq, stamp_ns, cdr| {
                if failed.is_some() {
                    return;
                }
                if stamp_ns > until_ns {
                    left_out += 1;
                    return;
                }
                let meta = Meta { seq, stamp_ns, fingerprint: out.fingerprint };
                // The CDR buffer goes to Zenoh as it is: no copy on the way (a second put shares it).
                let payload = zenoh::bytes::ZBytes::from(cdr);
                if let Some(r) = out.ros2.as_mut() {
                    r.seq += 1;
                    let att = ros2::attachment(r.seq, stamp_ns as i64, &r.gid);
                    if let Err(e) = r.publisher.put(payload.clone()).attachment(att).wait() {
                        failed = Some(anyhow::anyhow!("putting {} on Zenoh for ROS 2: {e}", tap.topic()));
                        return;
                    }
                }
                match out.publisher.put(payload).attachment(meta.encode().to_vec()).wait() {
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
