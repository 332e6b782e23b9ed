//! The bus runner: one node as a process over iceoryx2, paced in real time or by its turn in
//! the clock chain.

use std::any::Any;
use std::process::ExitCode;

use harvey_bus::{Bus, FramePublisher, FrameSubscriber, Pace, Publisher, Step, Subscriber, Waitable, Waiter};
use harvey_msgs::{FrameHeader, Message};

use super::{End, FrameView, InputPort, Io, Node, OutputPort, Ports, Wired, msg_of, vec_of};
use crate::{Resume, Rosout, Sent};

impl<T: Message> InputPort for Subscriber<T> {
    fn topic(&self) -> &'static str {
        Subscriber::topic(self)
    }

    fn take(&self, out: &mut dyn Any) -> anyhow::Result<()> {
        self.drain_into(vec_of::<T>(out, Subscriber::topic(self))?)?;
        Ok(())
    }

    fn waitable(&self) -> Option<&dyn Waitable> {
        Some(self)
    }
}

impl InputPort for FrameSubscriber {
    fn topic(&self) -> &'static str {
        FrameSubscriber::topic(self)
    }

    fn latest_frame(&self) -> anyhow::Result<Option<Box<dyn FrameView>>> {
        Ok(self.latest()?.map(|f| Box::new(f) as Box<dyn FrameView>))
    }

    fn waitable(&self) -> Option<&dyn Waitable> {
        Some(self)
    }
}

impl<T: Message> OutputPort for Publisher<T> {
    fn topic(&self) -> &'static str {
        Publisher::topic(self)
    }

    fn put(&self, msg: &dyn Any) -> anyhow::Result<()> {
        self.send(msg_of::<T>(msg, self.topic())?)?;
        Ok(())
    }
}

impl OutputPort for FramePublisher {
    fn topic(&self) -> &'static str {
        FramePublisher::topic(self)
    }

    fn put_frame(
        &self,
        header: FrameHeader,
        fill: &mut dyn FnMut(&mut [u8]) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let mut frame = self.loan(header)?;
        fill(frame.pixels_mut())?;
        frame.send()?;
        Ok(())
    }
}

/// Runs the node `build` makes as service `name` over the bus, until it is finished or told to
/// stop (SIGINT or SIGTERM; in deterministic mode once the turns granted have run), and
/// returns the exit code the node gives. `build` declares the node's ports; it runs after
/// logging is set up, so what it logs is seen.
pub fn run<N: Node>(
    name: &str,
    build: impl FnOnce(&mut Ports) -> anyhow::Result<N>,
) -> anyhow::Result<ExitCode> {
    crate::init_logging();
    let mut ports = Ports::default();
    let mut node = build(&mut ports)?;
    let bus = Bus::join(name)?;
    let wired = Wired {
        inputs: ports.inputs.iter().map(|i| i.open_bus(&bus)).collect::<anyhow::Result<_>>()?,
        outputs: ports.outputs.iter().map(|o| o.open_bus(&bus)).collect::<anyhow::Result<_>>()?,
        time_from: ports.time_from,
    };
    let mut rosout = Rosout::new(&bus, name)?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let wakes: Vec<&dyn Waitable> = wired.inputs.iter().filter_map(|i| i.waitable()).collect();
    let attachments = pace.attach(&waiter, &wakes)?;
    // A source's own rate, in real time only: a clock party's turns come from the chain.
    let interval = match ports.interval.filter(|_| pace.lockstep().is_none()) {
        Some(period) => Some(waiter.attach_interval(period)?),
        None => None,
    };
    let checkpoint = match N::CHECKPOINT_BYTES {
        0 => None,
        bytes => crate::Checkpoint::from_env(name, bytes)?,
    };
    let mut resume = Resume::with(checkpoint, || node.start())?;
    let mut sent = Sent::from_env(name)?;
    crate::notify_ready()?;

    let mut newest = 0;
    let persistent = std::env::var_os(crate::STATE_DIR_ENV).is_some();
    let resumed = resume.resumed();
    let (state, taken) = resume.parts();
    let mut io = Io { ports: &wired, taken, sent: &mut sent, tick: None, newest: &mut newest, persistent };
    node.begin(state, resumed, &mut io)?;
    let end = loop {
        if node.finished(resume.parts().0) {
            break End::Finished;
        }
        let tick = match pace.next(&waiter, None)? {
            Step::Go(tick) => tick,
            Step::Idle => continue,
            Step::Stop => break End::Stopped,
        };
        rosout.begin();
        let (state, taken) = resume.parts();
        let mut io = Io { ports: &wired, taken, sent: &mut sent, tick, newest: &mut newest, persistent };
        node.step(state, &mut io)?;
        let now = io.now();
        rosout.end(now)?;
        if resume.keeps() {
            node.save(resume.parts().0);
        }
        resume.tick_done()?;
        pace.done()?;
    };
    drop((attachments, interval));
    Ok(ExitCode::from(node.stopped(resume.parts().0, end)?))
}
