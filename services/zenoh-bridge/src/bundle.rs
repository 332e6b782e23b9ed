//! A tick's messages as one Zenoh sample, for the clock chain carried across hosts: what one
//! host's parties published in their share of a tick, in the taps' order, closed by the tick's
//! stamp, so that messages and progress travel together and in order (one publisher, one key).
//!
//! Layout, little-endian: `HVC`, the layout byte, the tick's stamp (u64), a kind byte (0 a tick,
//! 1 the end of the launch, 2 real time's messages as they came, 3 a restarted bridge asking for
//! the tick after the stamp), the message count (u32), then per message its topic (u8 length,
//! bytes), seq (u64), stamp (u64), the definition's fingerprint (u32) and its CDR (u32 length,
//! bytes).

use crate::wire::{LAYOUT, Meta};

const MAGIC: [u8; 3] = *b"HVC";

/// What a bundle says besides its messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The sender's share of this tick is done.
    Tick(u64),
    /// The sender's launch is ending: no more ticks.
    End,
    /// Real time: messages as they came, no tick.
    Live,
    /// The sender was restarted; its last finished tick is this one: the tick under way, if
    /// later, is to be sent again (it may have gone while nobody listened).
    Resync(u64),
}

/// A bundle being written.
#[derive(Default)]
pub struct Writer {
    buf: Vec<u8>,
    count: u32,
}

impl Writer {
    /// An empty bundle; its kind is given when it is finished.
    pub fn new() -> Self {
        let mut buf = Vec::with_capacity(1 << 16);
        buf.extend_from_slice(&MAGIC);
        buf.push(LAYOUT);
        buf.extend_from_slice(&[0u8; 9]);
        buf.extend_from_slice(&0u32.to_le_bytes());
        Self { buf, count: 0 }
    }

    pub fn push(&mut self, topic: &str, meta: &Meta, cdr: &[u8]) -> anyhow::Result<()> {
        let len = u8::try_from(topic.len()).map_err(|_| anyhow::anyhow!("topic name `{topic}` too long"))?;
        let cdr_len =
            u32::try_from(cdr.len()).map_err(|_| anyhow::anyhow!("{topic}: a message over 4 GiB"))?;
        self.buf.push(len);
        self.buf.extend_from_slice(topic.as_bytes());
        self.buf.extend_from_slice(&meta.seq.to_le_bytes());
        self.buf.extend_from_slice(&meta.stamp_ns.to_le_bytes());
        self.buf.extend_from_slice(&meta.fingerprint.to_le_bytes());
        self.buf.extend_from_slice(&cdr_len.to_le_bytes());
        self.buf.extend_from_slice(cdr);
        self.count += 1;
        Ok(())
    }

    /// Whether no message was pushed since the last bundle.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The bundle's bytes, closed by `kind`; the writer is empty again.
    pub fn finish(&mut self, kind: Kind) -> Vec<u8> {
        self.buf[13..17].copy_from_slice(&self.count.to_le_bytes());
        let (stamp, k) = match kind {
            Kind::Tick(t) => (t, 0u8),
            Kind::End => (0, 1),
            Kind::Live => (0, 2),
            Kind::Resync(t) => (t, 3),
        };
        self.buf[4..12].copy_from_slice(&stamp.to_le_bytes());
        self.buf[12] = k;
        let out = std::mem::replace(&mut self.buf, Self::new().buf);
        self.count = 0;
        out
    }
}

/// One message of a received bundle.
pub struct Item<'a> {
    pub topic: &'a str,
    pub meta: Meta,
    pub cdr: &'a [u8],
}

/// Reads a bundle: its kind and its messages, every length checked against what is left.
pub fn read(b: &[u8]) -> anyhow::Result<(Kind, Vec<Item<'_>>)> {
    anyhow::ensure!(
        b.len() >= 17 && b[..3] == MAGIC,
        "a {}-byte sample that is not a Harvey tick bundle",
        b.len()
    );
    anyhow::ensure!(
        b[3] == LAYOUT,
        "a bundle of layout v{}, this Harvey speaks v{LAYOUT}: another Harvey version",
        b[3]
    );
    let mut at = 4;
    let mut take = |n: usize, what: &str| -> anyhow::Result<&[u8]> {
        anyhow::ensure!(b.len() - at >= n, "bundle cut short at byte {at}: {what} needs {n} bytes");
        at += n;
        Ok(&b[at - n..at])
    };
    let u64_of = |s: &[u8]| s.iter().rev().fold(0u64, |v, &x| (v << 8) | u64::from(x));
    let stamp = u64_of(take(8, "the stamp")?);
    let kind = match take(1, "the kind")?[0] {
        0 => Kind::Tick(stamp),
        1 => Kind::End,
        2 => Kind::Live,
        3 => Kind::Resync(stamp),
        k => anyhow::bail!("bundle kind {k} unknown"),
    };
    let count = u64_of(take(4, "the count")?) as usize;
    let mut items = Vec::with_capacity(count.min(4096));
    for i in 0..count {
        let len = take(1, "a topic's length")?[0] as usize;
        let topic = std::str::from_utf8(take(len, "a topic")?)
            .map_err(|_| anyhow::anyhow!("message {i}: topic not UTF-8"))?;
        let seq = u64_of(take(8, "a seq")?);
        let stamp_ns = u64_of(take(8, "a stamp")?);
        let fingerprint = u64_of(take(4, "a fingerprint")?) as u32;
        let n = u64_of(take(4, "a length")?) as usize;
        let cdr = take(n, "a message")?;
        items.push(Item { topic, meta: Meta { seq, stamp_ns, fingerprint }, cdr });
    }
    anyhow::ensure!(at == b.len(), "{} bytes after the bundle's {count} messages", b.len() - at);
    Ok((kind, items))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundles_round_trip_and_damage_is_named() {
        let mut w = Writer::new();
        let m = Meta { seq: 3, stamp_ns: 50_000_000, fingerprint: 7 };
        w.push("odometry", &m, &[1, 2, 3]).expect("push");
        w.push("rosout", &Meta { seq: 9, ..m }, &[]).expect("push");
        let b = w.finish(Kind::Tick(50_000_000));
        let (kind, items) = read(&b).expect("reads");
        assert_eq!(kind, Kind::Tick(50_000_000));
        assert_eq!(items.len(), 2);
        assert_eq!((items[0].topic, items[0].meta, items[0].cdr), ("odometry", m, &[1u8, 2, 3][..]));
        assert_eq!((items[1].topic, items[1].meta.seq, items[1].cdr.len()), ("rosout", 9, 0));
        let end = w.finish(Kind::End);
        let (k, items) = read(&end).expect("end");
        assert_eq!((k, items.len()), (Kind::End, 0), "a finished writer starts empty");
        let (k, _) = read(&w.finish(Kind::Resync(7))).expect("resync");
        assert_eq!(k, Kind::Resync(7));
        let e = read(&b[..b.len() - 1]).err().expect("cut").to_string();
        assert!(e.contains("cut short"), "{e}");
        let mut v2 = b.clone();
        v2[3] = 2;
        assert!(read(&v2).err().expect("v2").to_string().contains("another Harvey version"));
        assert!(read(b"HVZ\x01").is_err());
    }
}
