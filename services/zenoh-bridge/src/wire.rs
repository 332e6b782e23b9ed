//! What crosses Zenoh (`docs/zenoh.md`): a topic's key expression, the sample's attachment
//! (layout version, sequence number, stamp, the message definition's fingerprint) and the
//! liveliness tokens by which hosts see what the others export. The payload is the message's
//! CDR exactly as the recorder writes it.

/// The attachment's first bytes: what a Harvey sample starts with.
pub const MAGIC: [u8; 3] = *b"HVZ";
/// The layout of keys and attachments this build speaks. A peer of another layout is refused.
pub const LAYOUT: u8 = 1;
/// Length of an attachment: magic, layout, seq, stamp, fingerprint.
pub const ATTACHMENT_LEN: usize = 3 + 1 + 8 + 8 + 4;

/// The key a topic's samples are put on: `<namespace>/<topic>` (`harvey/camera/frame`).
pub fn data_key(namespace: &str, topic: &str) -> String {
    format!("{namespace}/{topic}")
}

/// The liveliness token a host declares for each topic it exports:
/// `<namespace>/@live/v<layout>/<host>/<topic>`.
pub fn live_key(namespace: &str, host: &str, topic: &str) -> String {
    format!("{namespace}/@live/v{LAYOUT}/{host}/{topic}")
}

/// The liveliness tokens of every host and topic in `namespace`, of any layout.
pub fn live_all(namespace: &str) -> String {
    format!("{namespace}/@live/**")
}

/// `(layout, host, topic)` of a liveliness token's key, if it is one of `namespace`'s.
pub fn parse_live_key<'a>(namespace: &str, key: &'a str) -> Option<(&'a str, &'a str, &'a str)> {
    let rest = key.strip_prefix(namespace)?.strip_prefix("/@live/")?;
    let (layout, rest) = rest.split_once('/')?;
    let (host, topic) = rest.split_once('/')?;
    Some((layout.strip_prefix('v')?, host, topic))
}

/// The topic a data key names, if it is under `namespace`.
pub fn topic_of<'a>(namespace: &str, key: &'a str) -> Option<&'a str> {
    key.strip_prefix(namespace)?.strip_prefix('/')
}

/// A fingerprint of a message definition (CRC-32 of its type name and full `ros2msg` text):
/// samples of a topic whose definition differs from this build's are refused, not decoded into
/// a wrong message.
pub fn fingerprint(def: &harvey_cdr::Def) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(def.schema_name().as_bytes());
    h.update(b"\n");
    h.update(harvey_cdr::full_text(def).as_bytes());
    h.finalize()
}

/// A sample's attachment, decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Meta {
    pub seq: u64,
    pub stamp_ns: u64,
    pub fingerprint: u32,
}

impl Meta {
    pub fn encode(&self) -> [u8; ATTACHMENT_LEN] {
        let mut out = [0u8; ATTACHMENT_LEN];
        out[..3].copy_from_slice(&MAGIC);
        out[3] = LAYOUT;
        out[4..12].copy_from_slice(&self.seq.to_le_bytes());
        out[12..20].copy_from_slice(&self.stamp_ns.to_le_bytes());
        out[20..24].copy_from_slice(&self.fingerprint.to_le_bytes());
        out
    }

    /// Decodes an attachment, saying what is wrong with one that is not this layout's.
    pub fn decode(bytes: Option<&[u8]>) -> Result<Self, WireError> {
        let b = bytes.ok_or(WireError::NoAttachment)?;
        if b.len() < 4 || b[..3] != MAGIC {
            return Err(WireError::NotHarvey { len: b.len() });
        }
        if b[3] != LAYOUT {
            return Err(WireError::Layout { theirs: b[3] });
        }
        if b.len() != ATTACHMENT_LEN {
            return Err(WireError::Length { len: b.len() });
        }
        let u64_at = |i: usize| {
            let mut a = [0u8; 8];
            a.copy_from_slice(&b[i..i + 8]);
            u64::from_le_bytes(a)
        };
        let mut fp = [0u8; 4];
        fp.copy_from_slice(&b[20..24]);
        Ok(Self { seq: u64_at(4), stamp_ns: u64_at(12), fingerprint: u32::from_le_bytes(fp) })
    }
}

/// Why a sample is not one this bridge can take.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    #[error("no attachment: not a Harvey sample (another key layout or a foreign publisher)")]
    NoAttachment,
    #[error("a {len}-byte attachment without Harvey's `HVZ` mark: not a Harvey sample")]
    NotHarvey { len: usize },
    #[error("key layout v{theirs}, this Harvey speaks v{LAYOUT}: a peer of another Harvey version")]
    Layout { theirs: u8 },
    #[error("a {len}-byte attachment, layout v{LAYOUT} has {ATTACHMENT_LEN}")]
    Length { len: usize },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attachments_round_trip_and_foreign_ones_are_named() {
        let m = Meta { seq: 42, stamp_ns: 1_234_567_890, fingerprint: 0xdead_beef };
        let bytes = m.encode();
        assert_eq!(Meta::decode(Some(&bytes)), Ok(m));
        assert_eq!(Meta::decode(None), Err(WireError::NoAttachment));
        // rmw_zenoh's attachment (sequence number, timestamp, GID) is not Harvey's.
        let ros = [0u8; 33];
        assert_eq!(Meta::decode(Some(&ros)), Err(WireError::NotHarvey { len: 33 }));
        let mut other = bytes;
        other[3] = 2;
        let e = Meta::decode(Some(&other)).expect_err("layout v2");
        assert!(e.to_string().contains("another Harvey version"), "{e}");
        assert_eq!(Meta::decode(Some(&bytes[..20])), Err(WireError::Length { len: 20 }));
    }

    #[test]
    fn keys_name_namespace_host_and_topic() {
        assert_eq!(data_key("harvey", "camera/frame"), "harvey/camera/frame");
        assert_eq!(topic_of("harvey", "harvey/camera/frame"), Some("camera/frame"));
        assert_eq!(topic_of("harvey", "other/camera/frame"), None);
        let live = live_key("harvey", "b", "ums/map");
        assert_eq!(live, "harvey/@live/v1/b/ums/map");
        assert_eq!(parse_live_key("harvey", &live), Some(("1", "b", "ums/map")));
        assert_eq!(parse_live_key("harvey", "harvey/ums/map"), None);
    }

    #[test]
    fn fingerprints_tell_definitions_apart() {
        use harvey_cdr::Ros2Msg;
        let a = fingerprint(harvey_msgs::Odometry::DEF);
        assert_eq!(a, fingerprint(harvey_msgs::Odometry::DEF));
        assert_ne!(a, fingerprint(harvey_msgs::SonarRing::DEF));
        assert_ne!(a, fingerprint(harvey_cdr::image_def()));
    }
}
