//! What a chain bridge keeps across its own restart (`docs/zenoh.md`), in the supervisor's state
//! folder as every restartable party does (`docs/reliability.md`): the last tick whose share it
//! finished and the newest message it had taken off each publisher as of the last bundle that
//! left (`zenoh-bridge.ckpt`), how far it got publishing a bundle from the other host
//! (`zenoh-bridge-sent.ckpt`), and, on the other host, the last answer it sent, which it sends
//! again if the main host asks for that tick again (`zenoh-bridge-answer.bin`: the tick, a CRC-32
//! and the bundle; written aside and renamed).

use std::collections::HashMap;
use std::path::PathBuf;

use harvey_bus::Origin;
use harvey_runtime::{Checkpoint, Marks, STATE_DIR_ENV, Sent};
use serde::{Deserialize, Serialize};

/// The bridge's service name under the supervisor: its files' names.
const SERVICE: &str = "zenoh-bridge";
/// Bound on the checkpoint: the ticks and a mark per topic and publisher, some 70 bytes each
/// (a restarted service's publishers add theirs: thousands of restarts fit).
const SLOT_BYTES: usize = 1 << 20;
/// The key under which a bundle's published messages are noted: (tick, index in the bundle).
const BUNDLE: &str = "bundle";

/// Where the chain stands.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
pub struct Ticks {
    /// The last tick whose share is finished: on the main host, the other host's answer
    /// published (the turn is then passed on); on the other host, the answer sent.
    pub done: u64,
    /// The other host: a tick started on this host's chain and not answered yet.
    pub started: Option<u64>,
}

/// The bridge's kept state.
pub struct Keep {
    checkpoint: Option<Checkpoint>,
    ticks: Ticks,
    /// Per topic and publisher, the newest message taken (into a bundle, sent or not).
    taken: Marks,
    /// `taken` as of the last bundle that left: what is saved, so that a message taken into a
    /// bundle that a kill kept from leaving is taken again.
    left: Marks,
    resumed: bool,
    /// Real time: nothing is marked (a restart there loses what was under way anyway).
    live: bool,
    /// `topic@publisher` keys, made once per publisher.
    keys: HashMap<(&'static str, Origin), String>,
    sent: Sent,
    answer: Option<PathBuf>,
}

impl Keep {
    /// What a predecessor left, or a fresh start; nothing is kept when the bridge runs outside
    /// a supervisor.
    pub fn from_env() -> anyhow::Result<Self> {
        let mut checkpoint = Checkpoint::from_env(SERVICE, SLOT_BYTES)?;
        let saved = checkpoint.as_mut().map(|c| c.load::<(Ticks, Marks)>()).transpose()?.flatten();
        let resumed = saved.is_some();
        let (ticks, taken) = saved.unwrap_or_default();
        let sent = Sent::from_env(SERVICE)?;
        let answer =
            std::env::var_os(STATE_DIR_ENV).map(|d| PathBuf::from(d).join(format!("{SERVICE}-answer.bin")));
        let left = taken.clone();
        Ok(Self { checkpoint, ticks, taken, left, resumed, live: false, keys: HashMap::new(), sent, answer })
    }

    /// Whether a predecessor's state was found: this bridge was restarted mid-launch.
    pub fn resumed(&self) -> bool {
        self.resumed
    }

    pub fn ticks(&self) -> Ticks {
        self.ticks
    }

    /// Real time: nothing is marked or kept.
    pub fn go_live(&mut self) {
        self.live = true;
    }

    /// Whether a message taken off this host's bus is news (and notes it taken): a restarted
    /// bridge is handed every publisher's newest message again. Marked per publisher, since
    /// several publish on `rosout` and `tf` with numbers of their own.
    pub fn fresh(&mut self, topic: &'static str, from: Origin, stamp_ns: u64, seq: u64) -> bool {
        if self.live {
            return true;
        }
        let key = self.keys.entry((topic, from)).or_insert_with(|| format!("{topic}@{from}"));
        self.taken.fresh(key, stamp_ns, seq)
    }

    /// A bundle with what was taken so far is leaving.
    pub fn bundle_left(&mut self) {
        if !self.live {
            self.left.clone_from(&self.taken);
        }
    }

    /// Whether message `index` of the other host's bundle for `tick` still has to be published.
    pub fn due(&self, tick: u64, index: usize) -> bool {
        self.sent.due(BUNDLE, tick, index as u64)
    }

    /// Message `index` of the bundle for `tick` is published.
    pub fn published(&mut self, tick: u64, index: usize) -> anyhow::Result<()> {
        Ok(self.sent.done(BUNDLE, tick, index as u64)?)
    }

    /// Saves where the chain stands with what was taken (before the tick is reported done or
    /// the answer leaves).
    pub fn save(&mut self, ticks: Ticks) -> anyhow::Result<()> {
        self.ticks = ticks;
        match self.checkpoint.as_mut() {
            Some(c) => Ok(c.save(&(&self.ticks, &self.left))?),
            None => Ok(()),
        }
    }

    /// Keeps the answer for `tick` (the other host), before it is sent.
    pub fn keep_answer(&self, tick: u64, bundle: &[u8]) -> anyhow::Result<()> {
        let Some(path) = &self.answer else { return Ok(()) };
        let mut head = [0u8; 12];
        head[..8].copy_from_slice(&tick.to_le_bytes());
        head[8..].copy_from_slice(&crc32fast::hash(bundle).to_le_bytes());
        let aside = path.with_extension("new");
        // The header and the bundle as they are: no copy of the bundle per tick.
        std::fs::File::create(&aside)
            .and_then(|mut f| {
                std::io::Write::write_all(&mut f, &head)
                    .and_then(|()| std::io::Write::write_all(&mut f, bundle))
            })
            .map_err(|e| anyhow::anyhow!("keeping the answer in {}: {e}", aside.display()))?;
        std::fs::rename(&aside, path)
            .map_err(|e| anyhow::anyhow!("keeping the answer in {}: {e}", path.display()))
    }

    /// The last answer kept, with its tick, if its CRC checks.
    pub fn last_answer(&self) -> anyhow::Result<Option<(u64, Vec<u8>)>> {
        let Some(path) = &self.answer else { return Ok(None) };
        let bytes = match std::fs::read(path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => anyhow::bail!("reading the kept answer {}: {e}", path.display()),
        };
        let (Some(tick), Some(crc)) = (bytes.get(..8), bytes.get(8..12)) else {
            anyhow::bail!("{}: {} bytes, too short for a kept answer", path.display(), bytes.len())
        };
        let bundle = &bytes[12..];
        let crc = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
        anyhow::ensure!(
            crc32fast::hash(bundle) == crc,
            "{}: the kept answer's CRC does not check",
            path.display()
        );
        let tick = u64::from_le_bytes(tick.try_into().map_err(|_| anyhow::anyhow!("tick"))?);
        Ok(Some((tick, bundle.to_vec())))
    }
}
