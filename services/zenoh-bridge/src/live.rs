//! The chain between two hosts in real time (`docs/zenoh.md`): no turns; each side sends what
//! its host's services publish as it comes, in a `Live` bundle per wake-up, and publishes what
//! comes from the other.

use harvey_bus::{FdSource, Waiter, Wake};

use crate::bundle::Kind;
use crate::chain::{Chain, STALL_REPORT};

impl Chain<'_> {
    /// In real time: whatever this host's services publish goes to the other host as it comes,
    /// and what comes is published here, until the main host ends the launch (a `Live` bundle
    /// per wake-up; the order of each topic's messages is kept). The main host's bridge tells
    /// the other it ends when it is stopped.
    pub fn run_live(&mut self, main_side: bool) -> anyhow::Result<()> {
        self.keep.go_live();
        let waiter = Waiter::new()?;
        let bell = FdSource::new(self.inbox.bell())?;
        let mut attached = vec![waiter.attach(&bell)?];
        for t in self.taps {
            attached.push(waiter.attach(t.waitable())?);
        }
        loop {
            if waiter.wait(Some(STALL_REPORT))? == Wake::Shutdown {
                if main_side {
                    self.end()?;
                }
                return Ok(());
            }
            if self.has_news()? {
                let bundle = self.bundle(Kind::Live, u64::MAX)?;
                self.put(bundle)?;
            }
            while let Some(a) = self.inbox.next() {
                let bytes = a.payload.to_bytes();
                let (kind, items) = self.read(&bytes)?;
                self.publish(None, &items)?;
                if kind == Kind::End {
                    return Ok(());
                }
            }
        }
    }
}
