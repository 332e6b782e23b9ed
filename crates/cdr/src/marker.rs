//! ROS 2's `visualization_msgs/msg/MarkerArray`, as Jazzy defines it: the shapes (walls,
//! landmarks, the uncertainty polygon, the plan) Foxglove's 3D panel and RViz draw. Harvey writes
//! the fields a shape needs; the texture, UV and mesh fields go out empty.

use crate::codec::{Cdr, CdrError, CdrReader, CdrWriter};
use crate::geometry::{POINT, Point, QUATERNION, Quaternion, VECTOR3, read_seq, read_std_header, write_seq};
use crate::schema::Def;
use crate::types::{Ros2Msg, STD_HEADER, TIME, write_std_header};

static COLOR_RGBA: Def =
    Def { name: "std_msgs/ColorRGBA", text: "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n", deps: &[] };
static DURATION: Def =
    Def { name: "builtin_interfaces/Duration", text: "int32 sec\nuint32 nanosec\n", deps: &[] };
static POSE: Def = Def {
    name: "geometry_msgs/Pose",
    text: "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
    deps: &[&POINT, &QUATERNION],
};
static COMPRESSED_IMAGE: Def = Def {
    name: "sensor_msgs/CompressedImage",
    text: "std_msgs/Header header\nstring format\nuint8[] data\n",
    deps: &[&STD_HEADER],
};
static UV_COORDINATE: Def =
    Def { name: "visualization_msgs/UVCoordinate", text: "float32 u\nfloat32 v\n", deps: &[] };
static MESH_FILE: Def =
    Def { name: "visualization_msgs/MeshFile", text: "string filename\nuint8[] data\n", deps: &[] };
static MARKER: Def = Def {
    name: "visualization_msgs/Marker",
    text: "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
           int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
           int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n\
           int32 ARROW_STRIP=12\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n\
           std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n\
           geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
           builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
           std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\n\
           visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n\
           visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n",
    deps: &[
        &STD_HEADER,
        &POSE,
        &VECTOR3,
        &COLOR_RGBA,
        &DURATION,
        &POINT,
        &COMPRESSED_IMAGE,
        &UV_COORDINATE,
        &MESH_FILE,
        &TIME,
    ],
};
static MARKER_ARRAY: Def = Def {
    name: "visualization_msgs/MarkerArray",
    text: "visualization_msgs/Marker[] markers\n",
    deps: &[&MARKER],
};

/// A marker's shape (`Marker.type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(i32)]
pub enum MarkerKind {
    #[default]
    Cube = 1,
    Sphere = 2,
    Cylinder = 3,
    LineStrip = 4,
    LineList = 5,
    SphereList = 7,
    TextViewFacing = 9,
}

impl MarkerKind {
    fn from_raw(v: i32) -> Option<Self> {
        [Self::Cube, Self::Sphere, Self::Cylinder, Self::LineStrip, Self::LineList, Self::SphereList]
            .into_iter()
            .chain([Self::TextViewFacing])
            .find(|k| *k as i32 == v)
    }
}

/// `std_msgs/ColorRGBA`, each in 0..=1.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Colour(pub [f32; 4]);

/// One `visualization_msgs/Marker` (action ADD, no lifetime: it stands until replaced by one of
/// the same `ns` and `id`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Marker {
    pub stamp_ns: u64,
    pub frame_id: String,
    pub ns: String,
    pub id: i32,
    pub kind: MarkerKind,
    pub position: Point,
    pub orientation: Quaternion,
    pub scale: Point,
    pub colour: Colour,
    pub points: Vec<Point>,
    pub text: String,
}

impl Cdr for Marker {
    fn write(&self, w: &mut CdrWriter) {
        write_std_header(self.stamp_ns, &self.frame_id, w);
        w.string(&self.ns);
        [self.id, self.kind as i32, 0].write(w);
        self.position.write(w);
        self.orientation.write(w);
        self.scale.write(w);
        self.colour.0.write(w);
        [0i32, 0].write(w); // lifetime: none
        w.prim(0u8); // frame_locked
        write_seq(&self.points, w);
        w.prim(0u32); // colors
        w.string(""); // texture_resource
        write_std_header(0, "", w); // texture: an empty sensor_msgs/CompressedImage
        w.string("");
        w.byte_seq(&[]);
        w.prim(0u32); // uv_coordinates
        w.string(&self.text);
        w.string(""); // mesh_resource
        w.string(""); // mesh_file
        w.byte_seq(&[]);
        w.prim(0u8); // mesh_use_embedded_materials
    }

    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let (stamp_ns, frame_id) = read_std_header(r)?;
        let ns = r.string()?;
        let at = r.offset();
        let [id, kind, _action] = <[i32; 3]>::read(r)?;
        let kind = MarkerKind::from_raw(kind)
            .ok_or(CdrError::Invalid { at, what: format!("marker type {kind} is not one Harvey draws") })?;
        let (position, orientation, scale) = (Point::read(r)?, Quaternion::read(r)?, Point::read(r)?);
        let colour = Colour(<[f32; 4]>::read(r)?);
        let _lifetime = <[i32; 2]>::read(r)?;
        let _frame_locked = r.prim::<u8>()?;
        let points = read_seq(r, 24)?;
        let _colors = read_seq::<Colour>(r, 16)?;
        let _texture_resource = r.string()?;
        let _texture = (read_std_header(r)?, r.string()?, r.byte_seq()?);
        let _uv = read_seq::<[f32; 2]>(r, 8)?;
        let text = r.string()?;
        let _mesh = (r.string()?, r.string()?, r.byte_seq()?, r.prim::<u8>()?);
        Ok(Self { stamp_ns, frame_id, ns, id, kind, position, orientation, scale, colour, points, text })
    }
}

impl Cdr for Colour {
    fn write(&self, w: &mut CdrWriter) {
        self.0.write(w);
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self(<[f32; 4]>::read(r)?))
    }
}

/// `visualization_msgs/msg/MarkerArray`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MarkerArray(pub Vec<Marker>);

impl Cdr for MarkerArray {
    fn write(&self, w: &mut CdrWriter) {
        write_seq(&self.0, w);
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self(read_seq(r, 120)?))
    }
}

impl Ros2Msg for MarkerArray {
    const DEF: &'static Def = &MARKER_ARRAY;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Schema, TfMessage, Transform, decode, encode, full_text};

    fn wall() -> Marker {
        Marker {
            stamp_ns: 1_500_000_000,
            frame_id: "world".into(),
            ns: "walls".into(),
            id: 3,
            kind: MarkerKind::LineStrip,
            scale: Point([0.05, 0.0, 0.0]),
            colour: Colour([0.5, 0.5, 0.5, 1.0]),
            points: vec![Point([0.0, 0.0, 0.0]), Point([1.0, 2.0, 0.0])],
            text: "wall".into(),
            ..Default::default()
        }
    }

    #[test]
    fn markers_round_trip_and_decode_by_their_schema() {
        let array = MarkerArray(vec![wall(), Marker { id: 4, kind: MarkerKind::Sphere, ..wall() }]);
        let bytes = encode(&array, Vec::new());
        assert_eq!(decode::<MarkerArray>(&bytes).expect("decodes"), array);
        let schema = Schema::parse(MARKER_ARRAY.name, &full_text(&MARKER_ARRAY)).expect("schema");
        let v = schema.decode(&bytes).expect("decodes by schema");
        assert_eq!(v["markers"][0]["ns"], "walls");
        assert_eq!(v["markers"][0]["points"][1]["y"], 2.0);
        assert_eq!(v["markers"][1]["type"], 2);
        assert_eq!(v["markers"][1]["mesh_use_embedded_materials"], false);
        assert!(decode::<MarkerArray>(&bytes[..bytes.len() - 3]).is_err());
    }

    #[test]
    fn transforms_round_trip_and_decode_by_their_schema() {
        let tf = TfMessage(vec![Transform::planar(2_000_000_001, "world", "odom", [1.0, -2.0, 0.5])]);
        let bytes = encode(&tf, Vec::new());
        assert_eq!(decode::<TfMessage>(&bytes).expect("decodes"), tf);
        let def = <TfMessage as Ros2Msg>::DEF;
        let v = Schema::parse(def.name, &full_text(def)).expect("schema").decode(&bytes).expect("decodes");
        let t = &v["transforms"][0];
        assert_eq!(
            (t["header"]["frame_id"].as_str(), t["child_frame_id"].as_str()),
            (Some("world"), Some("odom"))
        );
        assert_eq!(t["header"]["stamp"]["nanosec"], 1);
        assert!((t["transform"]["rotation"]["z"].as_f64().unwrap_or(0.0) - 0.25f64.sin()).abs() < 1e-12);
    }

    #[test]
    fn a_garbled_sequence_length_is_refused_without_allocating() {
        let mut bytes = encode(&TfMessage::default(), Vec::new());
        bytes[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(decode::<TfMessage>(&bytes), Err(CdrError::Invalid { .. })));
    }
}
