//! From taps to Foxglove channels: one raw `cdr` channel per Harvey topic (`/sonar/ring`) with
//! the topic's `ros2msg` schema, as the recording's channels are, each message logged at its own
//! stamp; and the derived channels ([`crate::derive`]), advertised up front or created on first
//! use, the latched ones' last message kept for late subscribers ([`Latched`]).

use std::collections::BTreeMap;
use std::sync::Arc;

use foxglove::{ChannelBuilder, PartialMetadata, RawChannel, Schema};
use harvey_cdr::Def;

use crate::derive::Latched;
use crate::derive::{Derive, Derived};
use harvey_runtime::taps::{Tap, schema_of};

/// A raw channel of `cdr` messages of `def`, on `topic` (with its leading `/`).
pub fn channel(topic: &str, def: &Def) -> anyhow::Result<Arc<RawChannel>> {
    let (name, text) = schema_of(def);
    ChannelBuilder::new(topic)
        .message_encoding("cdr")
        .schema(Schema::new(name, "ros2msg", text.into_bytes()))
        .build_raw()
        .map_err(|e| anyhow::anyhow!("cannot make the Foxglove channel {topic}: {e}"))
}

/// What the bridge has sent on, per topic.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Counts {
    /// Messages taken from the bus.
    pub taken: u64,
    /// Messages logged to a subscribed client.
    pub sent: u64,
}

/// The channels of every tap, in the taps' order, and the derived ones.
pub struct Bridge {
    channels: Vec<Arc<RawChannel>>,
    counts: Vec<Counts>,
    hook: Box<dyn Derive>,
    /// Per derived topic: its channel, definition, and whether it is latched.
    derived: BTreeMap<String, (Arc<RawChannel>, &'static Def, bool)>,
    latched: Arc<Latched>,
    out: Vec<Derived>,
    buf: Vec<u8>,
    /// The newest stamp seen: the server's time.
    pub newest_ns: u64,
}

impl Bridge {
    /// Advertises a channel for each tap and each derived topic `hook` names up front; the last
    /// messages of latched ones go to `latched`.
    pub fn new(taps: &[Box<dyn Tap>], hook: Box<dyn Derive>, latched: Arc<Latched>) -> anyhow::Result<Self> {
        let channels = taps
            .iter()
            .map(|t| channel(&format!("/{}", t.topic()), t.def()))
            .collect::<anyhow::Result<_>>()?;
        let mut bridge = Self {
            channels,
            counts: vec![Counts::default(); taps.len()],
            hook,
            derived: BTreeMap::new(),
            latched,
            out: Vec::new(),
            buf: Vec::new(),
            newest_ns: 0,
        };
        for (topic, def, latched) in bridge.hook.advertised() {
            bridge.derived_channel(&topic, def)?;
            if let Some(d) = bridge.derived.get_mut(&topic) {
                d.2 = latched;
            }
        }
        Ok(bridge)
    }

    fn derived_channel(
        &mut self,
        topic: &str,
        def: &'static Def,
    ) -> anyhow::Result<(&Arc<RawChannel>, bool)> {
        if !self.derived.contains_key(topic) {
            anyhow::ensure!(
                !self.channels.iter().any(|c| c.topic() == topic),
                "a derived channel may not take a bus topic's name: {topic}"
            );
            self.derived.insert(topic.to_owned(), (channel(topic, def)?, def, false));
        }
        match self.derived.get(topic) {
            Some((c, d, latched)) if d.name == def.name => Ok((c, *latched)),
            Some((_, d, _)) => anyhow::bail!("derived channel {topic} is of {}, not {}", d.name, def.name),
            None => anyhow::bail!("derived channel {topic} was not made"),
        }
    }

    /// Takes every queued message of tap `i` and logs it to its channel (when a client is
    /// subscribed), and whatever the hook derives from it to theirs. A message is encoded only
    /// for a subscribed client or a hook that wants it in CDR: a camera frame's header goes to
    /// the hook as read in place, its pixels unencoded while nobody watches the frames.
    pub fn forward(&mut self, i: usize, tap: &dyn Tap) -> anyhow::Result<usize> {
        let Some(ch) = self.channels.get(i).cloned() else {
            anyhow::bail!("no channel for tap {i} ({})", tap.topic());
        };
        let topic = tap.topic();
        let wanted = self.hook.wants(topic);
        let encode = ch.has_sinks() || wanted;
        let (mut sent, mut newest, mut failed) = (0, self.newest_ns, None);
        let (hook, out) = (&mut self.hook, &mut self.out);
        let n = tap.take(encode, &mut self.buf, &mut |m| {
            newest = newest.max(m.stamp_ns);
            if encode && ch.has_sinks() {
                ch.log_with_meta(m.cdr, PartialMetadata::with_log_time(m.stamp_ns));
                sent += 1;
            }
            if let Some((h, pixel_bytes)) = m.frame
                && let Err(e) = hook.derive_frame(&h, pixel_bytes, out)
            {
                failed.get_or_insert(e);
            }
            if wanted && let Err(e) = hook.derive(topic, m.stamp_ns, m.cdr, out) {
                failed.get_or_insert(e);
            }
        })?;
        self.newest_ns = newest;
        let c = &mut self.counts[i];
        c.taken += n as u64;
        c.sent += sent;
        if let Some(e) = failed {
            // One bad derivation must not stop the bus topics: say so and go on.
            tracing::warn!(topic, "deriving from a message failed: {e:#}");
        }
        let mut out = std::mem::take(&mut self.out);
        for d in out.drain(..) {
            let store = self.latched.clone();
            let (ch, latched) = self.derived_channel(&d.topic, d.def)?;
            ch.log_with_meta(&d.cdr, PartialMetadata::with_log_time(d.stamp_ns));
            if latched {
                store.keep(ch, d.stamp_ns, &d.cdr);
            }
        }
        self.out = out;
        Ok(n)
    }

    /// Per tap, what was taken and sent.
    pub fn counts(&self) -> &[Counts] {
        &self.counts
    }

    /// The derived topics made so far.
    pub fn derived_topics(&self) -> Vec<&str> {
        self.derived.keys().map(String::as_str).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_bus::Bus;
    use harvey_msgs::{Header, Odometry, topics};

    /// A test's own bus domain (its prefix, to retire), the bridge's taps on it, and the
    /// latched store.
    fn domain(tag: &str) -> (String, Bus, Vec<Box<dyn harvey_runtime::taps::Tap>>, Arc<Latched>) {
        let prefix = format!("{tag}{}_", std::process::id());
        let bus = Bus::join_with_prefix("foxglove-bridge-test", &prefix).expect("bus");
        let taps = harvey_runtime::taps::open_all(&bus).expect("taps");
        (prefix, bus, taps, Arc::new(Latched::default()))
    }

    #[test]
    fn each_topic_has_its_channel_and_the_hook_its_own() {
        let (prefix, bus, taps, latched) = domain("tfoxbridge");
        let hook = Box::new(crate::derive::tests::Copy);
        let mut bridge = Bridge::new(&taps, hook, latched.clone()).expect("bridge");
        let topics: Vec<String> = bridge.channels.iter().map(|c| c.topic().to_owned()).collect();
        assert_eq!(topics, topics::ALL.iter().map(|t| format!("/{t}")).collect::<Vec<_>>());
        let ring = &bridge.channels[5];
        assert_eq!((ring.topic(), ring.message_encoding()), ("/sonar/ring", "cdr"));
        let schema = ring.schema().expect("schema");
        assert_eq!(
            (schema.name.as_str(), schema.encoding.as_str()),
            ("harvey_msgs/msg/SonarRing", "ros2msg")
        );
        assert_eq!(bridge.derived_topics(), ["/static"], "advertised before any message");

        let odometry = bus.publisher(topics::ODOMETRY).expect("publisher");
        for seq in 1..=3 {
            odometry
                .send(&Odometry { header: Header::new(seq, seq * 50_000_000), ..Default::default() })
                .expect("send");
        }
        let i = taps.iter().position(|t| t.topic() == topics::ODOMETRY.name).expect("odometry");
        assert_eq!(bridge.forward(i, taps[i].as_ref()).expect("forward"), 3);
        assert_eq!(bridge.counts()[i], Counts { taken: 3, sent: 0 }, "no client: nothing sent");
        assert_eq!(bridge.derived_topics(), ["/odometry_copy", "/static"]);
        assert_eq!(latched.len(), 0, "/odometry_copy is not latched");
        assert_eq!(bridge.newest_ns, 150_000_000);
        let clash = bridge.derived_channel("/odometry", <Odometry as harvey_cdr::Ros2Msg>::DEF);
        assert!(clash.is_err(), "a bus topic's name is refused");
        let other = bridge.derived_channel("/static", <Odometry as harvey_cdr::Ros2Msg>::DEF);
        assert!(other.is_err(), "one topic keeps one definition");
        drop((odometry, bridge, taps, bus));
        harvey_bus::retire_domain(&prefix).expect("retire");
    }

    #[test]
    fn unwatched_frames_bring_their_calibration_without_being_encoded() {
        let (prefix, bus, taps, latched) = domain("tfoxframes");
        let world = crate::derive::tests::world();
        let mut bridge =
            Bridge::new(&taps, crate::derive::hook(Some(&world)), latched.clone()).expect("bridge");
        let header = harvey_msgs::FrameHeader::new(1, 50_000_000, 64, 48, harvey_msgs::Encoding::Mono8);
        let frames = bus.frame_publisher(topics::CAMERA_FRAME, header.payload_len()).expect("publisher");
        let mut loan = frames.loan(header).expect("loan");
        loan.pixels_mut().fill(9);
        loan.send().expect("send");
        let i = taps.iter().position(|t| t.topic() == topics::CAMERA_FRAME.name).expect("frames");
        assert_eq!(bridge.forward(i, taps[i].as_ref()).expect("forward"), 1);
        assert_eq!(bridge.counts()[i], Counts { taken: 1, sent: 0 }, "no client: nothing sent");
        assert_eq!(bridge.buf.capacity(), 0, "nothing encoded");
        assert_eq!(latched.len(), 2, "the frame, the first message, brought /tf_static and the map");
        assert_eq!(bridge.newest_ns, 50_000_000);
        drop((frames, bridge, taps, bus));
        harvey_bus::retire_domain(&prefix).expect("retire");
    }
}
