//! The bus runner: one node as a process over iceoryx2, paced in real time or by its turn in
//! the clock chain.

use std::any::Any;

use harvey_bus::{Bus, Pace, Publisher, Step, Subscriber, Waitable, Waiter};
use harvey_msgs::Message;

use super::{Io, Node, Ports, Transport, msg_of, vec_of};
use crate::{Resume, Rosout, Sent};

/// An input opened on the bus.
pub(crate) trait BusInput {
    fn take(&self, out: &mut dyn Any) -> anyhow::Result<()>;
    fn waitable(&self) -> &dyn Waitable;
}

/// An output opened on the bus.
pub(crate) trait BusOutput {
    fn put(&self, msg: &dyn Any) -> anyhow::Result<()>;
}

impl<T: Message> BusInput for Subscriber<T> {
    fn take(&self, out: &mut dyn Any) -> anyhow::Result<()> {
        self.drain_into(vec_of::<T>(out, self.topic())?)?;
        Ok(())
    }

    fn waitable(&self) -> &dyn Waitable {
        self
    }
}

impl<T: Message> BusOutput for Publisher<T> {
    fn put(&self, msg: &dyn Any) -> anyhow::Result<()> {
        self.send(msg_of::<T>(msg, self.topic())?)?;
        Ok(())
    }
}

/// A node's ports on the bus.
struct Wired {
    inputs: Vec<Box<dyn BusInput>>,
    outputs: Vec<Box<dyn BusOutput>>,
}

impl Transport for Wired {
    fn take(&self, index: usize, out: &mut dyn Any) -> anyhow::Result<()> {
        self.inputs[index].take(out)
    }

    fn put(&self, index: usize, msg: &dyn Any) -> anyhow::Result<()> {
        self.outputs[index].put(msg)
    }
}

/// Runs the node `build` makes as service `name` over the bus, until SIGINT or SIGTERM (in
/// deterministic mode, once the turns granted have run). `build` declares the node's ports; it
/// runs after logging is set up, so what it logs is seen.
pub fn run<N: Node>(name: &str, build: impl FnOnce(&mut Ports) -> anyhow::Result<N>) -> anyhow::Result<()> {
    crate::init_logging();
    let mut ports = Ports::default();
    let mut node = build(&mut ports)?;
    let bus = Bus::join(name)?;
    let wired = Wired {
        inputs: ports.inputs.iter().map(|i| i.open_bus(&bus)).collect::<anyhow::Result<_>>()?,
        outputs: ports.outputs.iter().map(|o| o.open_bus(&bus)).collect::<anyhow::Result<_>>()?,
    };
    let mut rosout = Rosout::new(&bus, name)?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let wakes: Vec<&dyn Waitable> = wired.inputs.iter().map(|i| i.waitable()).collect();
    let attachments = pace.attach(&waiter, &wakes)?;
    let mut resume = Resume::from_env(name, N::CHECKPOINT_BYTES, || node.start())?;
    let mut sent = Sent::from_env(name)?;
    if resume.resumed() {
        node.resumed(resume.parts().0);
    }
    crate::notify_ready()?;

    let mut newest = 0;
    while let Step::Go(tick) = pace.next(&waiter, None)? {
        rosout.begin();
        let (state, taken) = resume.parts();
        let mut io = Io { transport: &wired, taken, sent: &mut sent, tick, newest: &mut newest };
        node.step(state, &mut io)?;
        let now = io.now();
        rosout.end(now)?;
        resume.tick_done()?;
        pace.done()?;
    }
    drop(attachments);
    node.stopped(resume.parts().0);
    Ok(())
}
