//! Importing: the chosen topics subscribed on Zenoh and published on the local bus
//! ([`Sinks`]). A sample that is not Harvey's, of another layout or another message definition
//! is refused, said once per topic and counted, and nothing else is lost.

use std::collections::BTreeMap;

use harvey_bus::Bus;

use crate::mailbox::Mailbox;
use crate::sinks::Sinks;
use crate::wire::{self, Meta};

/// Counts of one imported topic.
#[derive(Debug, Clone, Copy, Default)]
pub struct Counts {
    pub published: u64,
    pub refused: u64,
}

/// The imported topics of a bridge.
pub struct Importer {
    namespace: String,
    counts: BTreeMap<String, Counts>,
    mailbox: Mailbox,
}

impl Importer {
    /// Subscribes to the keys of `wanted` topics (checked: Harvey topics, published on `bus`
    /// through `sinks`).
    pub fn new(
        session: &zenoh::Session,
        bus: &Bus,
        sinks: &mut Sinks,
        namespace: &str,
        wanted: &[String],
    ) -> anyhow::Result<Self> {
        let mut mailbox = Mailbox::new()?;
        let mut counts = BTreeMap::new();
        for topic in wanted {
            sinks.get(bus, topic).map_err(|e| anyhow::anyhow!("--import: {e}"))?;
            mailbox.subscribe(session, &wire::data_key(namespace, topic))?;
            counts.insert(topic.clone(), Counts::default());
        }
        Ok(Self { namespace: namespace.to_owned(), counts, mailbox })
    }

    /// What wakes the bus thread when samples are queued.
    pub fn bell(&self) -> &std::os::unix::net::UnixStream {
        self.mailbox.bell()
    }

    /// Publishes every queued sample on the bus; returns how many.
    pub fn drain(&mut self, bus: &Bus, sinks: &mut Sinks) -> anyhow::Result<u64> {
        let mut n = 0;
        while let Some(a) = self.mailbox.next() {
            let Some(topic) = wire::topic_of(&self.namespace, &a.key) else { continue };
            let Some(count) = self.counts.get_mut(topic) else { continue };
            let sink = sinks.get(bus, topic)?;
            let meta = match Meta::decode(a.attachment.as_deref()) {
                Ok(m) if m.fingerprint == sink.fingerprint() => m,
                Ok(m) => {
                    let why = format!(
                        "message definition {:08x}, this build's is {:08x}: a peer of another Harvey version",
                        m.fingerprint,
                        sink.fingerprint()
                    );
                    refuse(topic, count, &why);
                    continue;
                }
                Err(e) => {
                    refuse(topic, count, &e.to_string());
                    continue;
                }
            };
            let pieces: Vec<&[u8]> = a.payload.slices().collect();
            match sink.publish(&meta, &pieces) {
                Ok(()) => {
                    count.published += 1;
                    n += 1;
                }
                Err(e) => refuse(topic, count, &format!("seq {}: {e}", meta.seq)),
            }
        }
        Ok(n)
    }

    pub fn counts(&self) -> &BTreeMap<String, Counts> {
        &self.counts
    }
}

/// Counts a refused sample; the first of a topic is said (an error), the rest only counted.
pub fn refuse(topic: &str, count: &mut Counts, why: &str) {
    if count.refused == 0 {
        tracing::error!(topic, "refusing samples from Zenoh: {why} (further ones are counted)");
    }
    count.refused += 1;
}
