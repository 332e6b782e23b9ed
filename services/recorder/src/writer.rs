//! The recorder's writer thread: compresses and writes batches to the MCAP file (with the topics
//! derived from them, `harvey_recording::derive`) and draws them into the Rerun file, off the bus
//! thread, so that a party of the clock chain is done with a
//! tick as soon as it has taken the tick's messages out of shared memory.

use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, SyncSender, sync_channel};
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

/// The bus thread's handle on the writer thread.
pub struct Writer {
    to_writer: Option<SyncSender<Batch>>,
    returned: Receiver<Batch>,
    thread: JoinHandle<anyhow::Result<Vec<ChannelStats>>>,
}

impl Writer {
    /// Starts the thread; it flushes both files at least every `flush_every` of wall time, and
    /// of the messages' own time (a deterministic run goes many times faster than real time:
    /// what a SIGKILL loses stays within the interval in both).
    pub fn start(files: Files, flush_every: Duration) -> anyhow::Result<Self> {
        let (to_writer, batches) = sync_channel(QUEUE);
        let (give_back, returned) = std::sync::mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("mcap-writer".into())
            .spawn(move || write_loop(files, &batches, &give_back, flush_every))?;
        Ok(Self { to_writer: Some(to_writer), returned, thread })
    }

    /// Queues a batch; waits if the writer is a whole queue behind.
    pub fn send(&self, batch: Batch) -> anyhow::Result<()> {
        let tx = self.to_writer.as_ref().ok_or_else(|| anyhow::anyhow!("writer already finished"))?;
        // A send fails only when the thread has ended, on an error that `finish` reports.
        let _ = tx.send(batch);
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
    batches: &Receiver<Batch>,
    give_back: &Sender<Batch>,
    flush_every: Duration,
) -> anyhow::Result<Vec<ChannelStats>> {
    let mut last_flush = Instant::now();
    // In message time every half interval: with what the bus thread holds before it hands a
    // batch over (a quarter), a SIGKILL loses less than the interval.
    let flush_ns = u64::try_from(flush_every.as_nanos() / 2).unwrap_or(u64::MAX);
    let (mut flushed_ns, mut newest_ns) = (0u64, 0u64);
    let mut derived = Vec::new();
    loop {
        match batches.recv_timeout(flush_every) {
            Ok(batch) => {
                newest_ns = batch.items.iter().map(|i| i.stamp_ns).fold(newest_ns, u64::max);
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
        if last_flush.elapsed() >= flush_every || newest_ns >= flushed_ns.saturating_add(flush_ns) {
            flushed_ns = newest_ns;
            files.mcap.flush()?;
            if let Some(rrd) = &files.rrd {
                rrd.flush()?;
            }
            last_flush = Instant::now();
        }
    }
    let stats = files.mcap.finish()?;
    if let Some(rrd) = files.rrd {
        rrd.finish()?;
    }
    Ok(stats)
}
