//! The simulator's ground truth read out of a run's recording (`/sim/truth`): the robot's true
//! poses in stamp order, and the true pose at a stamp.

use harvey_msgs::{Pose2, TruePose};

/// The simulator's true poses of a run, `(stamp_ns, world_from_robot)` in recorded order (the
/// simulator's clock's, so stamp order: the lookups rely on it).
#[derive(Debug, Default, Clone)]
pub struct Truth(pub Vec<(u64, Pose2)>);

impl Truth {
    /// The recorded topic of the simulator's truth (a pattern for a match on the topic).
    pub const TOPIC: &str = "/sim/truth";

    /// Takes `m`, a message on [`Truth::TOPIC`].
    pub fn push(&mut self, m: &mcap::Message<'_>) {
        let t = harvey_cdr::decode::<TruePose>(&m.data).expect("a TruePose on /sim/truth");
        self.0.push((t.header.stamp_ns, t.world_from_robot));
    }

    /// The true pose at or just before `stamp_ns`; `None` before the first one.
    pub fn at_or_before(&self, stamp_ns: u64) -> Option<Pose2> {
        let k = self.0.partition_point(|&(t, _)| t <= stamp_ns);
        k.checked_sub(1).map(|k| self.0[k].1)
    }

    /// The true pose at or just before `stamp_ns` (the first one before any).
    pub fn at(&self, stamp_ns: u64) -> Pose2 {
        self.at_or_before(stamp_ns).unwrap_or_else(|| self.first())
    }

    /// The first true pose.
    pub fn first(&self) -> Pose2 {
        self.0.first().expect("a true pose recorded on /sim/truth").1
    }

    /// The last true pose: where the robot truly ended.
    pub fn last(&self) -> Pose2 {
        self.0.last().expect("a true pose recorded on /sim/truth").1
    }
}
