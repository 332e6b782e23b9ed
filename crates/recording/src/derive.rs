//! Topics derived from the recorded ones, for the viewers that place things in 3D (Foxglove's 3D
//! panel, RViz): the transform tree `/tf` and `/tf_static` (`harvey_cdr::frames`) and the map,
//! the uncertainty polygon and the plan as `visualization_msgs/MarkerArray`s. Each derived
//! message follows the message it comes from, with its stamp, so a deterministic run (and its
//! replay) derives the same bytes; the recorder writes them and the Foxglove bridge serves them.

use std::collections::{BTreeMap, BTreeSet};

use harvey_cdr::{
    CameraInfo, CdrError, Def, MarkerArray, Ros2Msg, TfMessage, Transform, decode, decode_image, encode,
    frames,
};
use harvey_msgs::{
    FrameHeader, MissionStatus, Odometry, PlanSketch, Pose2, TruePose, UncertaintyMap, topics,
};
use harvey_world::World;

mod camera_info;
mod markers;

pub use camera_info::camera_info;
use camera_info::check_frame;

/// The derived topics (without the leading `/`), their types, and whether a late joiner must
/// still get their last message (`/tf_static`, the map: ROS's transient-local durability).
pub const TOPICS: [(&str, &Def, bool); 6] = [
    (TF, <TfMessage as Ros2Msg>::DEF, false),
    (TF_STATIC, <TfMessage as Ros2Msg>::DEF, true),
    (MAP_MARKERS, <MarkerArray as Ros2Msg>::DEF, true),
    (UNCERTAINTY_MARKERS, <MarkerArray as Ros2Msg>::DEF, false),
    (PLAN_MARKERS, <MarkerArray as Ros2Msg>::DEF, false),
    (CAMERA_INFO, <CameraInfo as Ros2Msg>::DEF, false),
];
pub const TF: &str = "tf";
pub const TF_STATIC: &str = "tf_static";
pub const MAP_MARKERS: &str = "markers/map";
pub const UNCERTAINTY_MARKERS: &str = "markers/uncertainty";
pub const PLAN_MARKERS: &str = "markers/plan";
/// Each camera frame's calibration (with the run's world): Foxglove places the image in 3D by it.
pub const CAMERA_INFO: &str = "camera/camera_info";

/// Where `topic` (with or without its leading `/`) is in [`TOPICS`].
pub fn index(topic: &str) -> Option<usize> {
    let t = topic.trim_start_matches('/');
    TOPICS.iter().position(|(name, ..)| *name == t)
}

/// Whether `topic` (with or without its leading `/`) is one the recorder derives.
pub fn is_derived(topic: &str) -> bool {
    index(topic).is_some()
}

/// A derived message: its topic, stamp (the source's), number on its topic, and CDR bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Derived {
    pub topic: &'static str,
    pub stamp_ns: u64,
    pub seq: u64,
    pub data: Vec<u8>,
}

/// The camera's optical frame seen from the robot: z ahead, x to the right, y down.
const OPTICAL_FROM_BASE: [f64; 4] = [-0.5, 0.5, -0.5, 0.5];

/// Derives the viewers' topics from the stream of recorded messages, in recording order.
#[derive(Debug)]
pub struct Deriver {
    world: Option<World>,
    started: bool,
    /// Recent odometry poses and executive estimates by stamp, each waiting for the other of its
    /// tick. Each derived message depends on its source alone, or on its source's tick: a
    /// recording that lost some messages lacks what they bring, and holds nothing that differs.
    odometry: BTreeMap<u64, Pose2>,
    estimates: BTreeMap<u64, Pose2>,
    seq: [u64; TOPICS.len()],
}

impl Deriver {
    /// With the run's world, the map's markers and the camera's height; without, neither.
    pub fn new(world: Option<&World>) -> Self {
        Self {
            world: world.cloned(),
            started: false,
            odometry: BTreeMap::new(),
            estimates: BTreeMap::new(),
            seq: [0; TOPICS.len()],
        }
    }

    fn push(&mut self, topic: &'static str, stamp_ns: u64, data: Vec<u8>, out: &mut Vec<Derived>) {
        let k = index(topic).unwrap_or(0);
        out.push(Derived { topic, stamp_ns, seq: self.seq[k], data });
        self.seq[k] += 1;
    }

    fn tf(&mut self, stamp_ns: u64, transforms: Vec<Transform>, out: &mut Vec<Derived>) {
        self.push(TF, stamp_ns, encode(&TfMessage(transforms), Vec::new()), out);
    }

    /// What the recorded message `data` on `topic` at `stamp_ns` adds; the first message of a
    /// recording also brings the static transforms and the map.
    pub fn derive(
        &mut self,
        topic: &str,
        stamp_ns: u64,
        data: &[u8],
        out: &mut Vec<Derived>,
    ) -> Result<(), CdrError> {
        let t = topic.trim_start_matches('/');
        if is_derived(t) {
            return Ok(());
        }
        self.start(stamp_ns, out);
        match t {
            _ if t == topics::SIM_TRUTH.name => {
                let p = decode::<TruePose>(data)?.world_from_robot;
                self.tf(stamp_ns, vec![planar(stamp_ns, frames::WORLD, frames::TRUTH, &p)], out);
            }
            _ if t == topics::ODOMETRY.name => {
                let p = decode::<Odometry>(data)?.world_from_robot;
                self.tf(stamp_ns, vec![planar(stamp_ns, frames::ODOM, frames::BASE_LINK, &p)], out);
                self.pair(stamp_ns, Some(p), None, out);
            }
            _ if t == topics::EXECUTIVE_STATUS.name => {
                let estimate = decode::<MissionStatus>(data)?.estimated;
                self.pair(stamp_ns, None, Some(estimate), out);
            }
            _ if t == topics::UMS_MAP.name => {
                let m = markers::uncertainty(stamp_ns, &decode::<UncertaintyMap>(data)?);
                self.push(UNCERTAINTY_MARKERS, stamp_ns, encode(&m, Vec::new()), out);
            }
            // Without the world, no calibration (and the frame is not decoded).
            _ if t == topics::CAMERA_FRAME.name && self.world.is_some() => {
                let (h, _) = decode_image(data)?;
                self.calibration(stamp_ns, &h, out);
            }
            _ if t == topics::EXECUTIVE_PLAN.name => {
                let m = markers::plan(stamp_ns, &decode::<PlanSketch>(data)?);
                self.push(PLAN_MARKERS, stamp_ns, encode(&m, Vec::new()), out);
            }
            _ => {}
        }
        Ok(())
    }

    /// What a camera frame adds, from its header alone (read in place; its pixels `pixel_bytes`
    /// long, not encoded): byte for byte what [`Deriver::derive`] makes of the frame recorded.
    pub fn derive_frame(
        &mut self,
        h: &FrameHeader,
        pixel_bytes: usize,
        out: &mut Vec<Derived>,
    ) -> Result<(), CdrError> {
        self.start(h.stamp_ns, out);
        if self.world.is_some() {
            check_frame(h, pixel_bytes)?;
            self.calibration(h.stamp_ns, h, out);
        }
        Ok(())
    }

    /// The first message of a recording brings the static transforms and the map.
    fn start(&mut self, stamp_ns: u64, out: &mut Vec<Derived>) {
        if !self.started {
            self.started = true;
            self.statics(stamp_ns, out);
        }
    }

    /// `/camera/camera_info` for the frame `h`, logged at `stamp_ns`, when the world is known.
    fn calibration(&mut self, stamp_ns: u64, h: &FrameHeader, out: &mut Vec<Derived>) {
        let Some(world) = &self.world else { return };
        let info = camera_info(h, world);
        self.push(CAMERA_INFO, stamp_ns, encode(&info, Vec::new()), out);
    }

    /// `world → odom` once a tick's odometry and estimate are both in, whichever came first (a
    /// live observer may take them in either order).
    fn pair(
        &mut self,
        stamp_ns: u64,
        odometry: Option<Pose2>,
        estimate: Option<Pose2>,
        out: &mut Vec<Derived>,
    ) {
        let (o, e) = match (odometry, estimate) {
            (Some(o), _) => (Some(o), self.estimates.remove(&stamp_ns)),
            (None, Some(e)) => (self.odometry.remove(&stamp_ns), Some(e)),
            (None, None) => (None, None),
        };
        match (o, e) {
            (Some(o), Some(e)) => {
                let c = correction(&e, &o);
                self.tf(stamp_ns, vec![Transform::planar(stamp_ns, frames::WORLD, frames::ODOM, c)], out);
            }
            (Some(o), None) => keep_recent(&mut self.odometry, stamp_ns, o),
            (None, Some(e)) => keep_recent(&mut self.estimates, stamp_ns, e),
            (None, None) => {}
        }
    }

    /// `/tf_static` (the camera on the robot) and, with the world, the map and the robot at its start.
    fn statics(&mut self, stamp_ns: u64, out: &mut Vec<Derived>) {
        let height_m = self.world.as_ref().map_or(0.0, |w| w.camera.height_m);
        let camera = Transform {
            stamp_ns: 0,
            parent: frames::BASE_LINK.into(),
            child: frames::CAMERA.into(),
            translation: harvey_cdr::Point([0.0, 0.0, height_m]),
            rotation: harvey_cdr::Quaternion(OPTICAL_FROM_BASE),
        };
        self.push(TF_STATIC, stamp_ns, encode(&TfMessage(vec![camera]), Vec::new()), out);
        let Some(world) = &self.world else { return };
        // Stamped 0 like the camera's mount: it holds from the start, whenever it was written.
        let map = markers::map(0, world);
        // Until odometry says otherwise, the robot is where the world file starts it, from the
        // run's time 0 (a standing vision request is stamped 0, before the first tick).
        let start = planar(0, frames::ODOM, frames::BASE_LINK, &world.start);
        let world_odom = Transform::planar(0, frames::WORLD, frames::ODOM, [0.0; 3]);
        self.push(MAP_MARKERS, stamp_ns, encode(&map, Vec::new()), out);
        self.tf(stamp_ns, vec![world_odom, start], out);
    }
}

/// Ticks a half of a pair waits for the other: a live observer takes a topic's queue whole, so
/// the other half comes within a queue's worth of ticks or not at all.
const PAIR_WAIT: usize = 64;

fn keep_recent(waiting: &mut BTreeMap<u64, Pose2>, stamp_ns: u64, p: Pose2) {
    waiting.insert(stamp_ns, p);
    while waiting.len() > PAIR_WAIT {
        waiting.pop_first();
    }
}

fn planar(stamp_ns: u64, parent: &str, child: &str, p: &Pose2) -> Transform {
    Transform::planar(stamp_ns, parent, child, [p.x_m, p.y_m, p.heading_rad])
}

/// `world → odom` such that `world → odom → base_link` puts the robot at `estimate` when
/// odometry has it at `odometry`: `estimate ∘ odometry⁻¹`.
fn correction(estimate: &Pose2, odometry: &Pose2) -> [f64; 3] {
    let c = estimate.compose(&odometry.inverse());
    [c.x_m, c.y_m, c.heading_rad]
}

/// The derived messages a continued recording lacks: `derived` is what the deriver made of the
/// carried-over messages, `present` the (topic, log time, sequence) of the derived messages the
/// killed recorder had already written (a source may have reached the file, its derived message
/// not).
pub fn missing(derived: Vec<Derived>, present: &BTreeSet<(String, u64, u32)>) -> Vec<Derived> {
    derived
        .into_iter()
        .filter(|d| !present.contains(&(d.topic.to_owned(), d.stamp_ns, d.seq as u32)))
        .collect()
}

#[cfg(test)]
mod tests;
