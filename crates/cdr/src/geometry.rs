//! ROS 2's transform messages (`tf2_msgs/msg/TFMessage` of `geometry_msgs/msg/TransformStamped`),
//! as Jazzy defines them: what Foxglove's 3D panel and ROS tools place every `frame_id` with.

use crate::codec::{Cdr, CdrError, CdrReader, CdrWriter};
use crate::schema::Def;
use crate::types::{Ros2Msg, STD_HEADER, write_std_header};

pub(crate) static VECTOR3: Def =
    Def { name: "geometry_msgs/Vector3", text: "float64 x\nfloat64 y\nfloat64 z\n", deps: &[] };
pub(crate) static POINT: Def =
    Def { name: "geometry_msgs/Point", text: "float64 x\nfloat64 y\nfloat64 z\n", deps: &[] };
pub(crate) static QUATERNION: Def =
    Def { name: "geometry_msgs/Quaternion", text: "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n", deps: &[] };
static TRANSFORM: Def = Def {
    name: "geometry_msgs/Transform",
    text: "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
    deps: &[&VECTOR3, &QUATERNION],
};
static TRANSFORM_STAMPED: Def = Def {
    name: "geometry_msgs/TransformStamped",
    text: "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
    deps: &[&STD_HEADER, &TRANSFORM],
};
static TF_MESSAGE: Def = Def {
    name: "tf2_msgs/TFMessage",
    text: "geometry_msgs/TransformStamped[] transforms\n",
    deps: &[&TRANSFORM_STAMPED],
};

/// A point or vector (`geometry_msgs/Point`, `Vector3`: the same three doubles).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Point(pub [f64; 3]);

/// A rotation (`geometry_msgs/Quaternion`), `[x, y, z, w]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quaternion(pub [f64; 4]);

impl Default for Quaternion {
    fn default() -> Self {
        Self([0.0, 0.0, 0.0, 1.0])
    }
}

impl Quaternion {
    /// A turn of `rad` about z (counter-clockwise seen from above).
    pub fn yaw(rad: f64) -> Self {
        Self([0.0, 0.0, (rad / 2.0).sin(), (rad / 2.0).cos()])
    }
}

impl Cdr for Point {
    fn write(&self, w: &mut CdrWriter) {
        self.0.write(w);
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self(<[f64; 3]>::read(r)?))
    }
}

impl Cdr for Quaternion {
    fn write(&self, w: &mut CdrWriter) {
        self.0.write(w);
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self(<[f64; 4]>::read(r)?))
    }
}

/// One `geometry_msgs/TransformStamped`: where `child` is in `parent` at `stamp_ns`.
#[derive(Debug, Clone, PartialEq)]
pub struct Transform {
    pub stamp_ns: u64,
    pub parent: String,
    pub child: String,
    pub translation: Point,
    pub rotation: Quaternion,
}

impl Transform {
    /// A robot-like pose on the floor: at `(x, y)`, turned `heading_rad` about z.
    pub fn planar(stamp_ns: u64, parent: &str, child: &str, [x, y, heading_rad]: [f64; 3]) -> Self {
        Self {
            stamp_ns,
            parent: parent.to_owned(),
            child: child.to_owned(),
            translation: Point([x, y, 0.0]),
            rotation: Quaternion::yaw(heading_rad),
        }
    }
}

pub(crate) fn read_std_header(r: &mut CdrReader<'_>) -> Result<(u64, String), CdrError> {
    let sec = r.prim::<i32>()?;
    let nanosec = r.prim::<u32>()?;
    let frame_id = r.string()?;
    Ok((u64::try_from(sec).unwrap_or(0) * 1_000_000_000 + u64::from(nanosec), frame_id))
}

impl Cdr for Transform {
    fn write(&self, w: &mut CdrWriter) {
        write_std_header(self.stamp_ns, &self.parent, w);
        w.string(&self.child);
        self.translation.write(w);
        self.rotation.write(w);
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let (stamp_ns, parent) = read_std_header(r)?;
        let child = r.string()?;
        Ok(Self { stamp_ns, parent, child, translation: Point::read(r)?, rotation: Quaternion::read(r)? })
    }
}

/// `tf2_msgs/msg/TFMessage`: what `/tf` and `/tf_static` carry.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TfMessage(pub Vec<Transform>);

/// A CDR sequence of messages: its length, then each.
pub(crate) fn write_seq<T: Cdr>(items: &[T], w: &mut CdrWriter) {
    w.prim(items.len() as u32);
    items.iter().for_each(|t| t.write(w));
}

/// Reads a sequence of messages, refusing a length the bytes left cannot hold (at least
/// `min_bytes` each), so a garbled count allocates nothing.
pub(crate) fn read_seq<T: Cdr>(r: &mut CdrReader<'_>, min_bytes: usize) -> Result<Vec<T>, CdrError> {
    let at = r.offset();
    let n = r.prim::<u32>()? as usize;
    if n.saturating_mul(min_bytes) > r.remaining() {
        return Err(CdrError::Invalid { at, what: format!("a sequence of {n} cannot fit in the message") });
    }
    (0..n).map(|_| T::read(r)).collect()
}

impl Cdr for TfMessage {
    fn write(&self, w: &mut CdrWriter) {
        write_seq(&self.0, w);
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self(read_seq(r, 8 + 4 + 4 + 56)?))
    }
}

impl Ros2Msg for TfMessage {
    const DEF: &'static Def = &TF_MESSAGE;
}
