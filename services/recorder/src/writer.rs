//! The recorder's writer thread: compresses and writes batches to the MCAP file (with the topics
//! derived from them, `harvey_recording::derive`) and draws them into the Rerun file, off the bus
//! thread, so that a party of the clock chain is done with a
//! tick as soon as it has taken the tick's messages out of shared memory.

use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, SyncSender, sync_channel};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use harvey_recording::derive::{self, Derived, Deriver};
use harvey_recording::draw::draw_recorded;
use harvey_recording::rrd::RrdWriter;
use harvey_recording::{Channel, ChannelStats, Recorder};

use crate::taps::Batch;

/// Batches the bus thread may queue before it waits for the writer: enough to ride out a slow
/// write, few enough to bound the memory held (a batch may hold 1080p frames).
const QUEUE: usize = 8;

/// The files, owned by the writer thread.
pub struct Files {
    pub mcap: Recorder,
    pub rrd: Option<RrdWriter>,
    pub deriver: Deriver,
    /// The derived topics' channels, in `derive::TOPICS`' order.
    pub derived: Vec<Channel>,
}

impl Files {
    /// Records derived messages on their channels.
    pub fn record_derived(&mut self, messages: impl IntoIterator<Item = Derived>) -> anyhow::Result<()> {
        for d in messages {
            let ch = derive::index(d.topic).and_then(|k| self.derived.get(k).copied());
            let ch = ch.ok_or_else(|| anyhow::anyhow!("no channel for the derived topic {}", d.topic))?;
            self.mcap.record_encoded(ch, d.seq, d.stamp_ns, &d.data)?;
        }
        Ok(())
    }
}

/// What the bus thread hands the writer thread.
enum ToWriter {
    /// A batch, and the tick it holds every message up to (`u64::MAX` in real time).
    Batch(Batch, u64),
    /// Flush what has been written now: the bus thread waits for it.
    Flush,
}

/// The newest message time on disk (flushed), which the bus thread may wait on.
#[derive(Default)]
struct Flushed {
    ns: Mutex<u64>,
    changed: Condvar,
}

impl Flushed {
    fn set(&self, ns: u64) {
        if let Ok(mut g) = self.ns.lock() {
            *g = ns;
        }
        self.changed.notify_all();
    }
}

/// The bus thread's handle on the writer thread.
pub struct Writer {
    to_writer: Option<SyncSender<ToWriter>>,
    returned: Receiver<Batch>,
    flushed: Arc<Flushed>,
    /// The newest tick handed over whole (0 in real time).
    sent_until: std::cell::Cell<u64>,
    thread: JoinHandle<anyhow::Result<Vec<ChannelStats>>>,
}

impl Writer {
    /// Starts the thread; it flushes both files at least every `flush_every` of wall time, and
    /// of the messages' own time (a deterministic run goes many times faster than real time:
    /// what a SIGKILL loses stays within the interval in both).
    pub fn start(files: Files, flush_every: Duration) -> anyhow::Result<Self> {
        let (to_writer, batches) = sync_channel(QUEUE);
        let (give_back, returned) = std::sync::mpsc::channel();
        let flushed = Arc::new(Flushed::default());
        let on_disk = Arc::clone(&flushed);
        let thread = std::thread::Builder::new()
            .name("mcap-writer".into())
            .spawn(move || write_loop(files, &batches, &give_back, &on_disk, flush_every))?;
        Ok(Self { to_writer: Some(to_writer), returned, flushed, sent_until: 0.into(), thread })
    }

    /// Queues a batch holding every message up to tick `until_ns` (`u64::MAX`: real time, no
    /// ticks); waits if the writer is a whole queue behind.
    pub fn send(&self, batch: Batch, until_ns: u64) -> anyhow::Result<()> {
        if until_ns != u64::MAX {
            self.sent_until.set(self.sent_until.get().max(until_ns));
        }
        self.put(ToWriter::Batch(batch, until_ns))
    }

    fn put(&self, m: ToWriter) -> anyhow::Result<()> {
        let tx = self.to_writer.as_ref().ok_or_else(|| anyhow::anyhow!("writer already finished"))?;
        // A send fails only when the thread has ended, on an error that `finish` reports.
        let _ = tx.send(m);
        Ok(())
    }

    /// Waits until what is on disk reaches tick `ns - lag_ns` (or all that was sent, if less),
    /// asking the writer to flush if it is not there yet: in a run faster than real time the
    /// queue alone could hold several flush intervals of messages, all lost to a SIGKILL.
    /// Returns at once when the writer thread has ended (its error comes from `finish`).
    pub fn bound_lag(&self, ns: u64, lag_ns: u64) -> anyhow::Result<()> {
        let want = ns.saturating_sub(lag_ns).min(self.sent_until.get());
        let on_disk = |s: &Self| s.flushed.ns.lock().map(|g| *g).unwrap_or(u64::MAX);
        if on_disk(self) >= want || self.thread.is_finished() {
            return Ok(());
        }
        self.put(ToWriter::Flush)?;
        let mut g = self.flushed.ns.lock().map_err(|_| anyhow::anyhow!("the writer thread panicked"))?;
        while *g < want && !self.thread.is_finished() {
            // The timeout only re-checks that the thread still runs.
            g = self
                .flushed
                .changed
                .wait_timeout(g, Duration::from_millis(100))
                .map_err(|_| anyhow::anyhow!("the writer thread panicked"))?
                .0;
        }
        Ok(())
    }

    /// A batch the writer is done with, if any, for reuse.
    pub fn returned(&self) -> Option<Batch> {
        self.returned.try_recv().ok()
    }

    /// Writes what is queued, finishes both files and returns the per-channel counts.
    pub fn finish(mut self) -> anyhow::Result<Vec<ChannelStats>> {
        drop(self.to_writer.take());
        self.thread.join().map_err(|_| anyhow::anyhow!("the writer thread panicked"))?
    }
}

fn write_loop(
    mut files: Files,
    batches: &Receiver<ToWriter>,
    give_back: &Sender<Batch>,
    on_disk: &Flushed,
    flush_every: Duration,
) -> anyhow::Result<Vec<ChannelStats>> {
    let mut last_flush = Instant::now();
    // In message time every half interval: with what the bus thread holds before it hands a
    // batch over (a quarter), a SIGKILL loses less than the interval.
    let flush_ns = u64::try_from(flush_every.as_nanos() / 2).unwrap_or(u64::MAX);
    let (mut flushed_ns, mut newest_ns) = (0u64, 0u64);
    let mut derived = Vec::new();
    loop {
        let mut asked = false;
        match batches.recv_timeout(flush_every) {
            Ok(ToWriter::Flush) => asked = true,
            Ok(ToWriter::Batch(batch, until_ns)) => {
                newest_ns = batch.items.iter().map(|i| i.stamp_ns).fold(newest_ns, u64::max);
                if until_ns != u64::MAX {
                    newest_ns = newest_ns.max(until_ns);
                }
                for i in &batch.items {
                    files.mcap.record_encoded(i.channel, i.seq, i.stamp_ns, &i.data)?;
                    files
                        .deriver
                        .derive(i.topic, i.stamp_ns, &i.data, &mut derived)
                        .map_err(|e| anyhow::anyhow!("deriving from {}: {e}", i.topic))?;
                    files.record_derived(derived.drain(..))?;
                    if let Some(rrd) = files.rrd.as_mut() {
                        draw_recorded(rrd, i.topic, &i.data)
                            .map_err(|e| anyhow::anyhow!("drawing {}: {e}", i.topic))?;
                    }
                }
                if let Some(rrd) = files.rrd.as_mut() {
                    for &(stamp, ms) in &batch.loop_latency {
                        rrd.loop_latency(stamp, ms)?;
                    }
                }
                let _ = give_back.send(batch);
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => break,
        }
        if asked || last_flush.elapsed() >= flush_every || newest_ns >= flushed_ns.saturating_add(flush_ns) {
            flushed_ns = newest_ns;
            files.mcap.flush()?;
            if let Some(rrd) = &files.rrd {
                rrd.flush()?;
            }
            on_disk.set(flushed_ns);
            last_flush = Instant::now();
        }
    }
    let stats = files.mcap.finish()?;
    if let Some(rrd) = files.rrd {
        rrd.finish()?;
    }
    Ok(stats)
}
