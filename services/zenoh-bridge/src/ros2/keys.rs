//! rmw_zenoh's names and bytes for a ROS 2 publisher (`rmw_zenoh_cpp`, ROS 2 Jazzy, 0.2.4 and
//! later): the key a topic's samples are put on, the attachment each sample carries, and the
//! liveliness tokens of a node and of its publisher that `ros2 node list` / `ros2 topic list`
//! read. Sources: `rmw_zenoh_cpp/src/detail/liveliness_utils.cpp` (`TopicInfo`, `Entity`,
//! `mangle_name`, `qos_to_keyexpr`), `attachment_helpers.cpp`, `qos.cpp`, `type_support_common.hpp`
//! and the examples in `docs/design.md`.

use std::fmt::Write as _;

use anyhow::{Result, anyhow, bail, ensure};

/// rmw_zenoh's GIDs are `RMW_GID_STORAGE_SIZE` (16 in Jazzy) bytes.
pub const GID_LEN: usize = 16;

/// The type name rmw_zenoh puts in keys, as DDS's CDR type support names it:
/// `sensor_msgs::msg::dds_::Image_` (`_create_type_name` in `type_support_common.hpp`).
pub fn dds_type_name(def: &harvey_cdr::Def) -> Result<String> {
    let name = def.schema_name();
    match name.split('/').collect::<Vec<_>>().as_slice() {
        [pkg, sub, ty] => Ok(format!("{pkg}::{sub}::dds_::{ty}_")),
        _ => bail!("`{name}` is not a message type name (`pkg/msg/Type`)"),
    }
}

/// The key a topic's samples are put on: `<domain>/<topic>/<dds type>/<RIHS01 hash>`, the topic
/// without its leading slash (`TopicInfo`'s `topic_keyexpr_`).
pub fn data_key(domain_id: u32, topic: &str, def: &harvey_cdr::Def) -> Result<String> {
    let topic = fully_qualified(topic)?;
    let hash = super::rihs01(def)?;
    Ok(format!("{domain_id}/{}/{}/{hash}", &topic[1..], dds_type_name(def)?))
}

/// What rmw_zenoh attaches to each sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Attachment {
    /// The publisher's count of samples, from 1.
    pub seq: i64,
    /// When the sample was published, ns since the UNIX epoch.
    pub source_timestamp_ns: i64,
    /// The publisher's GID.
    pub gid: [u8; GID_LEN],
}

/// The attachment's bytes, as `AttachmentData::serialize_to_zbytes` writes them with
/// `zenoh::ext::Serializer`: the sequence number and the timestamp as i64 little-endian, then
/// the GID as a `std::array`, which zenoh-cpp serialises as a sequence: its length as a LEB128
/// varint (one byte, 16) and the bytes. 33 bytes.
pub fn attachment(seq: i64, source_timestamp_ns: i64, gid: &[u8; GID_LEN]) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 + 8 + 1 + GID_LEN);
    out.extend_from_slice(&seq.to_le_bytes());
    out.extend_from_slice(&source_timestamp_ns.to_le_bytes());
    out.push(GID_LEN as u8);
    out.extend_from_slice(gid);
    out
}

/// Reads an attachment as rmw_zenoh does (bytes after the GID are ignored, as it ignores them).
pub fn parse_attachment(bytes: &[u8]) -> Result<Attachment> {
    if bytes.first() == Some(&15) && bytes.get(1..16) == Some(b"sequence_number".as_slice()) {
        bail!("attachment in rmw_zenoh's format before Jazzy 0.2.4 (named fields), not supported");
    }
    let i64_at = |at: usize| -> Result<i64> {
        let b =
            bytes.get(at..at + 8).ok_or_else(|| anyhow!("attachment of {} bytes is short", bytes.len()))?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(i64::from_le_bytes(a))
    };
    let (seq, source_timestamp_ns) = (i64_at(0)?, i64_at(8)?);
    let (mut len, mut shift, mut at) = (0u64, 0u32, 16usize);
    loop {
        let b = *bytes.get(at).ok_or_else(|| anyhow!("attachment ends inside the GID's length"))?;
        ensure!(shift < 64, "attachment's GID length does not end");
        len |= u64::from(b & 0x7f) << shift;
        (shift, at) = (shift + 7, at + 1);
        if b & 0x80 == 0 {
            break;
        }
    }
    ensure!(len == GID_LEN as u64, "attachment's GID has {len} bytes, not {GID_LEN}");
    let gid = bytes
        .get(at..at + GID_LEN)
        .and_then(|g| <[u8; GID_LEN]>::try_from(g).ok())
        .ok_or_else(|| anyhow!("attachment of {} bytes ends inside the GID", bytes.len()))?;
    Ok(Attachment { seq, source_timestamp_ns, gid })
}

/// QoS policies with `rmw/types.h`'s values (those a profile has once rmw_zenoh has replaced
/// its system defaults: `QoS::best_available_qos` in `qos.cpp`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reliability {
    Reliable = 1,
    BestEffort = 2,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Durability {
    TransientLocal = 1,
    Volatile = 2,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum History {
    KeepLast = 1,
    KeepAll = 2,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Liveliness {
    Automatic = 1,
    ManualByTopic = 3,
}

/// `rmw_time_t`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RmwTime {
    pub sec: u64,
    pub nsec: u64,
}

impl RmwTime {
    /// `RMW_DURATION_INFINITE` (`rmw/time.h`).
    pub const INFINITE: Self = Self { sec: 9_223_372_036, nsec: 854_775_807 };
}

/// A publisher's QoS profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    pub reliability: Reliability,
    pub durability: Durability,
    pub history: History,
    /// 0 is the system default, which rmw_zenoh makes 42.
    pub depth: usize,
    pub deadline: RmwTime,
    pub lifespan: RmwTime,
    pub liveliness: Liveliness,
    pub liveliness_lease_duration: RmwTime,
}

impl Default for Qos {
    /// rmw_zenoh's default profile (`qos.cpp`): reliable, volatile, keep last 42, no deadline,
    /// lifespan or lease, automatic liveliness. Its token's QoS part is empty: `::,:,:,:,,`.
    fn default() -> Self {
        Self {
            reliability: Reliability::Reliable,
            durability: Durability::Volatile,
            history: History::KeepLast,
            depth: 42,
            deadline: RmwTime::INFINITE,
            lifespan: RmwTime::INFINITE,
            liveliness: Liveliness::Automatic,
            liveliness_lease_duration: RmwTime::INFINITE,
        }
    }
}

impl Qos {
    /// rclcpp's default for a publisher of that depth (reliable, volatile, keep last).
    pub fn keep_last(depth: usize) -> Self {
        Self { depth, ..Self::default() }
    }
}

/// A QoS profile as a liveliness token carries it (`qos_to_keyexpr`): each value that differs
/// from rmw_zenoh's default, empty where it is the default, as `reliability:durability:
/// history,depth:deadline_s,deadline_ns:lifespan_s,lifespan_ns:liveliness,lease_s,lease_ns`.
pub fn qos_key(qos: &Qos) -> String {
    let d = Qos::default();
    let depth = if qos.depth == 0 { d.depth } else { qos.depth };
    let mut out = String::new();
    let mut part = |differs: bool, value: u64, then: &str| {
        if differs {
            let _ = write!(out, "{value}");
        }
        out.push_str(then);
    };
    part(qos.reliability != d.reliability, qos.reliability as u64, ":");
    part(qos.durability != d.durability, qos.durability as u64, ":");
    part(qos.history != d.history, qos.history as u64, ",");
    part(depth != d.depth, depth as u64, ":");
    part(qos.deadline.sec != d.deadline.sec, qos.deadline.sec, ",");
    part(qos.deadline.nsec != d.deadline.nsec, qos.deadline.nsec, ":");
    part(qos.lifespan.sec != d.lifespan.sec, qos.lifespan.sec, ",");
    part(qos.lifespan.nsec != d.lifespan.nsec, qos.lifespan.nsec, ":");
    part(qos.liveliness != d.liveliness, qos.liveliness as u64, ",");
    let lease = (qos.liveliness_lease_duration, d.liveliness_lease_duration);
    part(lease.0.sec != lease.1.sec, lease.0.sec, ",");
    part(lease.0.nsec != lease.1.nsec, lease.0.nsec, "");
    out
}

/// The ROS 2 node the bridge's entities belong to.
#[derive(Debug, Clone, Copy)]
pub struct Node<'a> {
    /// `ROS_DOMAIN_ID`.
    pub domain_id: u32,
    /// The Zenoh session's id as Zenoh prints it (`ZenohId`'s `Display`: lowercase hex).
    pub zid: &'a str,
    /// The node's id within the session (rmw_zenoh counts entities from 0).
    pub node_id: u64,
    /// The SROS enclave, `/` when none (`""` is taken as `/`).
    pub enclave: &'a str,
    /// The namespace, `/` when none (`""` is taken as `/`).
    pub namespace: &'a str,
    pub name: &'a str,
}

/// The liveliness token of a node (`NN`): `@ros2_lv/<domain>/<zid>/<node id>/<node id>/NN/
/// <mangled enclave>/<mangled namespace>/<name>`.
pub fn node_token(node: &Node<'_>) -> Result<String> {
    Ok(format!("{}/NN/{}", node_prefix(node, node.node_id)?, node_part(node)?))
}

/// The liveliness token of a publisher (`MP`) of `node` on `topic` (its fully qualified name,
/// the leading `/` optional), of type `type_name` ([`dds_type_name`]) and hash `type_hash`
/// ([`super::rihs01`]): the node's parts, then the mangled topic, the type, the hash and
/// [`qos_key`].
pub fn publisher_token(
    node: &Node<'_>,
    entity_id: u64,
    topic: &str,
    type_name: &str,
    type_hash: &str,
    qos: &Qos,
) -> Result<String> {
    let hex = type_hash.strip_prefix("RIHS01_").unwrap_or("");
    ensure!(
        hex.len() == 64 && hex.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)),
        "`{type_hash}` is not a RIHS01 type hash"
    );
    ensure!(
        !type_name.is_empty() && type_name.chars().all(|c| c.is_ascii_alphanumeric() || "_:".contains(c)),
        "`{type_name}` is not a DDS type name (`pkg::msg::dds_::Type_`)"
    );
    let topic = mangle(&fully_qualified(topic)?);
    let node_part = node_part(node)?;
    let qos = qos_key(qos);
    Ok(format!("{}/MP/{node_part}/{topic}/{type_name}/{type_hash}/{qos}", node_prefix(node, entity_id)?))
}

/// `@ros2_lv/<domain>/<zid>/<node id>/<entity id>`.
fn node_prefix(node: &Node<'_>, entity_id: u64) -> Result<String> {
    let zid = node.zid;
    ensure!(
        (1..=32).contains(&zid.len())
            && zid.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)),
        "`{zid}` is not a Zenoh session id (lowercase hex)"
    );
    Ok(format!("@ros2_lv/{}/{zid}/{}/{entity_id}", node.domain_id, node.node_id))
}

/// `<mangled enclave>/<mangled namespace>/<name>`.
fn node_part(node: &Node<'_>) -> Result<String> {
    ensure!(is_token(node.name), "`{}` is not a node name", node.name);
    let enclave = absolute(node.enclave, "enclave")?;
    let namespace = absolute(node.namespace, "namespace")?;
    Ok(format!("{}/{}/{}", mangle(&enclave), mangle(&namespace), node.name))
}

/// rmw_zenoh's `mangle_name`: every `/` becomes `%`.
fn mangle(name: &str) -> String {
    name.replace('/', "%")
}

/// A ROS name token: letters, digits and `_`, not starting with a digit.
fn is_token(s: &str) -> bool {
    s.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `/`, or `/a/b` for `a/b` or `/a/b`.
fn absolute(name: &str, what: &str) -> Result<String> {
    let rel = name.strip_prefix('/').unwrap_or(name);
    if rel.is_empty() {
        return Ok("/".to_owned());
    }
    ensure!(rel.split('/').all(is_token), "`{name}` is not a ROS {what}");
    Ok(format!("/{rel}"))
}

/// A topic's fully qualified name, `/a/b`.
fn fully_qualified(topic: &str) -> Result<String> {
    let t = absolute(topic, "topic name")?;
    ensure!(t != "/", "a topic name cannot be empty");
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_cdr::Def;

    static STRING: Def = Def { name: "std_msgs/String", text: "string data\n", deps: &[] };
    const STRING_HASH: &str = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18";
    const IMAGE_HASH: &str = "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47";

    #[test]
    fn data_keys_are_rmw_zenohs() {
        // rmw_zenoh's docs/design.md, "Topic and Service name mapping to Zenoh key expressions":
        // demo_nodes_cpp's `chatter`, plain and under the namespace `/robot1`. The hash is
        // computed here from `string data`: it is ROS 2's own for std_msgs/msg/String.
        assert_eq!(
            data_key(0, "chatter", &STRING).expect("key"),
            format!("0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}")
        );
        assert_eq!(
            data_key(0, "/robot1/chatter", &STRING).expect("key"),
            format!("0/robot1/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}")
        );
        let image = harvey_cdr::image_def();
        assert_eq!(dds_type_name(image).expect("name"), "sensor_msgs::msg::dds_::Image_");
        assert_eq!(
            data_key(7, "camera/frame", image).expect("key"),
            format!("7/camera/frame/sensor_msgs::msg::dds_::Image_/{IMAGE_HASH}")
        );
        for bad in ["", "/", "a//b", "a/b/", "camera/1frame", "a b", "a/*"] {
            assert!(data_key(0, bad, image).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn liveliness_tokens_are_rmw_zenohs() {
        // docs/design.md, "Graph Cache": the listener node and the talker's publisher
        // (demo_nodes_cpp's talker publishes with depth 7, the listener subscribes with 10).
        let listener = Node {
            domain_id: 2,
            zid: "aac3178e146ba6f1fc6e6a4085e77f21",
            node_id: 0,
            enclave: "/",
            namespace: "/",
            name: "listener",
        };
        assert_eq!(
            node_token(&listener).expect("token"),
            "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"
        );
        let talker = Node { zid: "8b20917502ee955ac4476e0266340d5c", name: "talker", ..listener };
        let ty = dds_type_name(&STRING).expect("name");
        assert_eq!(
            publisher_token(&talker, 10, "/chatter", &ty, STRING_HASH, &Qos::keep_last(7)).expect("token"),
            format!(
                "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/\
                 std_msgs::msg::dds_::String_/{STRING_HASH}/::,7:,:,:,,"
            )
        );
        assert_eq!(qos_key(&Qos::keep_last(10)), "::,10:,:,:,,");
        // An empty enclave or namespace is rcl's `/`; a namespace and a topic are mangled.
        let harvey =
            Node { domain_id: 0, zid: "1f", node_id: 3, enclave: "", namespace: "robot1", name: "harvey" };
        let token = publisher_token(
            &harvey,
            4,
            "camera/frame",
            "sensor_msgs::msg::dds_::Image_",
            IMAGE_HASH,
            &Qos::default(),
        )
        .expect("token");
        assert_eq!(
            token,
            format!(
                "@ros2_lv/0/1f/3/4/MP/%/%robot1/harvey/%camera%frame/\
                 sensor_msgs::msg::dds_::Image_/{IMAGE_HASH}/::,:,:,:,,"
            )
        );
    }

    #[test]
    fn bad_token_parts_are_refused() {
        let node = Node { domain_id: 0, zid: "1f", node_id: 0, enclave: "/", namespace: "/", name: "n" };
        let token = |node: &Node<'_>, ty: &str, hash: &str| {
            publisher_token(node, 1, "t", ty, hash, &Qos::default()).map_err(|e| e.to_string())
        };
        let ty = "std_msgs::msg::dds_::String_";
        assert!(token(&node, ty, STRING_HASH).is_ok());
        assert!(token(&Node { zid: "1F", ..node }, ty, STRING_HASH).expect_err("zid").contains("session id"));
        assert!(token(&Node { zid: "", ..node }, ty, STRING_HASH).is_err());
        assert!(
            token(&Node { name: "my-node", ..node }, ty, STRING_HASH)
                .expect_err("name")
                .contains("node name")
        );
        assert!(
            token(&Node { namespace: "/a//b", ..node }, ty, STRING_HASH)
                .expect_err("ns")
                .contains("namespace")
        );
        assert!(token(&node, "std_msgs/String", STRING_HASH).expect_err("type").contains("DDS type name"));
        assert!(token(&node, ty, "RIHS01_00").expect_err("hash").contains("RIHS01 type hash"));
        assert!(token(&node, ty, &STRING_HASH.to_uppercase()).is_err());
    }

    #[test]
    fn qos_differing_from_rmw_zenohs_default_is_spelled_out() {
        // `qos_to_keyexpr`: each value only where it differs from rmw_zenoh's default profile.
        assert_eq!(qos_key(&Qos::default()), "::,:,:,:,,");
        assert_eq!(qos_key(&Qos::keep_last(0)), "::,:,:,:,,", "depth 0 is rmw_zenoh's 42");
        let qos = Qos {
            reliability: Reliability::BestEffort,
            durability: Durability::TransientLocal,
            history: History::KeepAll,
            depth: 1,
            deadline: RmwTime { sec: 1, nsec: 500 },
            liveliness: Liveliness::ManualByTopic,
            liveliness_lease_duration: RmwTime { sec: 2, nsec: 0 },
            ..Qos::default()
        };
        assert_eq!(qos_key(&qos), "2:1:2,1:1,500:,:3,2,0");
    }

    #[test]
    fn attachments_are_rmw_zenohs() {
        // Python eclipse-zenoh 1.10.2's `zenoh.ext.z_serialize((Int64(7), Int64(stamp),
        // [UInt8(b) for b in 0xa0..0xb0]))` (`scripts/rihs01_oracle.py`): the bytes
        // `zenoh::ext::Serializer` writes for AttachmentData's int64, int64, std::array<uint8_t, 16>.
        let gid: [u8; GID_LEN] = std::array::from_fn(|k| 0xa0 + k as u8);
        let bytes = attachment(7, 1_700_000_000_123_456_789, &gid);
        let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(hex, "070000000000000015cd853dfe9c971710a0a1a2a3a4a5a6a7a8a9aaabacadaeaf");
        let back = parse_attachment(&bytes).expect("parses");
        assert_eq!(back, Attachment { seq: 7, source_timestamp_ns: 1_700_000_000_123_456_789, gid });
        let round = attachment(-1, i64::MIN, &[0xff; GID_LEN]);
        assert_eq!(
            parse_attachment(&round).expect("parses"),
            Attachment { seq: -1, source_timestamp_ns: i64::MIN, gid: [0xff; GID_LEN] }
        );
        let err = |b: &[u8]| parse_attachment(b).expect_err("refused").to_string();
        assert!(err(&bytes[..10]).contains("short"));
        assert!(err(&bytes[..16]).contains("inside the GID's length"));
        assert!(err(&bytes[..30]).contains("ends inside the GID"));
        let mut long = bytes.clone();
        long[16] = 15;
        assert!(err(&long).contains("15 bytes, not 16"));
        // A length as a longer LEB128 varint (0x90 0x00 is 16) is still 16.
        let mut wide = bytes[..16].to_vec();
        wide.extend_from_slice(&[0x90, 0x00]);
        wide.extend_from_slice(&gid);
        assert_eq!(parse_attachment(&wide).expect("parses").gid, gid);
        // Before Jazzy 0.2.4 each field followed its name as a string.
        let mut old = vec![15u8];
        old.extend_from_slice(b"sequence_number");
        old.extend_from_slice(&7i64.to_le_bytes());
        assert!(err(&old).contains("before Jazzy 0.2.4"));
    }
}
