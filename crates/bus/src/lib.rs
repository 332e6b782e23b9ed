//! Harvey's bus: typed publish/subscribe over iceoryx2 shared memory, the only crate that
//! touches iceoryx2.
//!
//! - [`Bus`] is one process's membership in a *domain*: an iceoryx2 node whose resources all
//!   carry the domain's prefix. Tests and launches pick a unique prefix, so they never see each
//!   other and leftovers of a killed run cannot break the next.
//! - Every topic is a publish-subscribe service plus an event service of the same name: a
//!   publisher notifies after each send, so subscribers sleep in a [`Waiter`] instead of polling.
//! - Frames are `[u8]` slices with a [`harvey_msgs::FrameHeader`]: the producer writes pixels
//!   straight into the loaned shared-memory slice, the consumer reads them in place.
//! - [`Pace`] runs a service's loop on its inputs (real time) or on its turn in the clock chain
//!   of deterministic mode ([`Lockstep`]).

mod clock;
mod domain;
mod error;
mod frames;
mod listing;
mod pubsub;
mod reoffer;
mod shm;
mod waiter;

pub use clock::{AFTER_ENV, CLOCK_ENV, Lockstep, PARTY_ENV, Pace, Step, lockstep_from_env};
pub use domain::{
    Bus, DEFAULT_PREFIX, NodeInfo, PREFIX_ENV, cleanup_dead_nodes, is_plain_name, live_nodes, retire_domain,
    validate_prefix,
};
pub use error::BusError;
pub use frames::{Frame, FrameLoan, FramePublisher, FrameSubscriber};
pub use listing::{TopicInfo, iceoryx2_config, topics};
pub use pubsub::{Origin, Publisher, Subscriber};
pub use reoffer::{REOFFERED, ReofferRequests, Reoffers};
pub use shm::domain_files;
pub use waiter::{Attachment, FdSource, Waitable, Waiter, Wake};

pub type Result<T> = std::result::Result<T, BusError>;
