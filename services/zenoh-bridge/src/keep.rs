//! What a chain bridge keeps across its own restart (`docs/zenoh.md`), in the supervisor's state
//! folder as every restartable party does (`docs/reliability.md`): the last tick whose share it
//! finished and the messages it had taken off each publisher (`zenoh-bridge.ckpt`), how far it
//! got publishing a bundle from the other host (`zenoh-bridge-sent.ckpt`), and, on the other
//! host, the last answer it sent, which it sends again if the main host asks for that tick again
//! (`zenoh-bridge-answer.bin`: the tick, a CRC-32 and the bundle; written aside and renamed).

use std::path::PathBuf;

use harvey_bus::Origin;
use harvey_runtime::{Resume, STATE_DIR_ENV, Sent};
use serde::{Deserialize, Serialize};

/// The bridge's service name under the supervisor: its files' names.
const SERVICE: &str = "zenoh-bridge";
/// Bound on the checkpoint: the ticks and one mark per topic and publisher (tens of them).
const SLOT_BYTES: usize = 64 << 10;
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
    resume: Resume<Ticks>,
    sent: Sent,
    answer: Option<PathBuf>,
}

impl Keep {
    /// What a predecessor left, or a fresh start; nothing is kept when the bridge runs outside
    /// a supervisor.
    pub fn from_env() -> anyhow::Result<Self> {
        let resume = Resume::from_env(SERVICE, SLOT_BYTES, Ticks::default)?;
        let sent = Sent::from_env(SERVICE)?;
        let answer =
            std::env::var_os(STATE_DIR_ENV).map(|d| PathBuf::from(d).join(format!("{SERVICE}-answer.bin")));
        Ok(Self { resume, sent, answer })
    }

    /// Whether a predecessor's state was found: this bridge was restarted mid-launch.
    pub fn resumed(&self) -> bool {
        self.resume.resumed()
    }

    pub fn ticks(&mut self) -> Ticks {
        *self.resume.state()
    }

    /// Whether a message taken off this host's bus is news (and notes it taken): a restarted
    /// bridge is handed every publisher's newest message again. Marked per publisher, since
    /// several publish on `rosout` and `tf` with numbers of their own.
    pub fn fresh(&mut self, topic: &str, from: Origin, stamp_ns: u64, seq: u64) -> bool {
        self.resume.fresh(&format!("{topic}@{from}"), stamp_ns, seq)
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
        *self.resume.state() = ticks;
        Ok(self.resume.tick_done()?)
    }

    /// Keeps the answer for `tick` (the other host), before it is sent.
    pub fn keep_answer(&self, tick: u64, bundle: &[u8]) -> anyhow::Result<()> {
        let Some(path) = &self.answer else { return Ok(()) };
        let mut bytes = Vec::with_capacity(12 + bundle.len());
        bytes.extend_from_slice(&tick.to_le_bytes());
        bytes.extend_from_slice(&crc32fast::hash(bundle).to_le_bytes());
        bytes.extend_from_slice(bundle);
        let aside = path.with_extension("new");
        std::fs::write(&aside, &bytes)
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
