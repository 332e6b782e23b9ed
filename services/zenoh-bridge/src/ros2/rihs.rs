//! RIHS01 type hashes (REP 2011) of `ros2msg` schema texts, as `rosidl_generator_type_description`
//! computes them: the type description of the message and of every type it refers to (field
//! names, type ids, capacities, nested type names; no constants, defaults or comments), written
//! as the JSON rosidl hashes, then SHA-256.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use anyhow::{Context, Result, anyhow, bail, ensure};
use sha2::{Digest, Sha256};

/// rosidl's `FieldType` ids (`type_description_interfaces/msg/FieldType.msg`, copied in
/// `rosidl_generator_type_description/__init__.py` as `FIELD_TYPE_NAME_TO_ID`; rosbags'
/// `TIDMAP` agrees). A `.msg` `char` is `uint8` (rosidl_adapter's `MSG_TYPE_TO_IDL`), `byte`
/// is `octet`.
const NESTED: u8 = 1;
const BOUNDED_STRING: u8 = 21;
const BOUNDED_WSTRING: u8 = 22;
/// Added to a value type's id: a fixed array, a bounded sequence, an unbounded sequence.
const ARRAY: u8 = 48;
const BOUNDED_SEQUENCE: u8 = 96;
const UNBOUNDED_SEQUENCE: u8 = 144;

fn primitive_id(ty: &str) -> Option<u8> {
    Some(match ty {
        "int8" => 2,
        "uint8" | "char" => 3,
        "int16" => 4,
        "uint16" => 5,
        "int32" => 6,
        "uint32" => 7,
        "int64" => 8,
        "uint64" => 9,
        "float32" => 10,
        "float64" => 11,
        "bool" => 15,
        "byte" => 16,
        "string" => 17,
        "wstring" => 18,
        _ => return None,
    })
}

/// A field's `FieldType`.
#[derive(Debug, Clone, PartialEq, Eq)]
struct FieldType {
    type_id: u8,
    capacity: u64,
    string_capacity: u64,
    nested_type_name: String,
}

type Fields = Vec<(String, FieldType)>;

/// The RIHS01 hash (`RIHS01_<64 hex>`) of a Harvey message definition.
pub fn rihs01(def: &harvey_cdr::Def) -> Result<String> {
    rihs01_of_text(&def.schema_name(), &harvey_cdr::full_text(def))
}

/// The RIHS01 hash of message `name` (`pkg/msg/Type` or `pkg/Type`) by its full `ros2msg`
/// schema text (its own definition, then each dependency after a line of `=` and
/// `MSG: pkg/Type`, as rosbag2 and MCAP carry it).
pub fn rihs01_of_text(name: &str, text: &str) -> Result<String> {
    let json = description_json(name, text).with_context(|| format!("type hash of {name}"))?;
    let digest = Sha256::digest(json.as_bytes());
    let mut out = String::from("RIHS01_");
    for b in digest {
        let _ = write!(out, "{b:02x}");
    }
    Ok(out)
}

/// The JSON rosidl hashes: `json.dumps` of the type description without default values,
/// separators `", "` and `": "`, keys in rosidl's order, referenced types sorted by name.
fn description_json(name: &str, text: &str) -> Result<String> {
    let root = normalize(name)?;
    let defs = parse_schema(&root, text)?;
    let mut referenced = BTreeSet::new();
    let mut queue = vec![root.clone()];
    while let Some(ty) = queue.pop() {
        let fields = defs.get(&ty).ok_or_else(|| anyhow!("`{ty}` is used but not defined in the schema"))?;
        for (_, f) in fields {
            if !f.nested_type_name.is_empty() && referenced.insert(f.nested_type_name.clone()) {
                queue.push(f.nested_type_name.clone());
            }
        }
    }
    let mut out = String::from("{\"type_description\": ");
    write_struct(&mut out, &root, &defs[&root]);
    out.push_str(", \"referenced_type_descriptions\": [");
    for (k, ty) in referenced.iter().enumerate() {
        if k > 0 {
            out.push_str(", ");
        }
        write_struct(&mut out, ty, &defs[ty]);
    }
    out.push_str("]}");
    Ok(out)
}

/// Names and nested type names are checked to be plain identifiers and `/`: no JSON escaping.
fn write_struct(out: &mut String, name: &str, fields: &Fields) {
    let _ = write!(out, "{{\"type_name\": \"{name}\", \"fields\": [");
    for (k, (field, t)) in fields.iter().enumerate() {
        let sep = if k > 0 { ", " } else { "" };
        let _ = write!(
            out,
            "{sep}{{\"name\": \"{field}\", \"type\": {{\"type_id\": {}, \"capacity\": {}, \
             \"string_capacity\": {}, \"nested_type_name\": \"{}\"}}}}",
            t.type_id, t.capacity, t.string_capacity, t.nested_type_name
        );
    }
    out.push_str("]}");
}

fn is_identifier(s: &str) -> bool {
    s.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `pkg/Type` and `pkg/msg/Type` both name `pkg/msg/Type`.
fn normalize(name: &str) -> Result<String> {
    let parts: Vec<&str> = name.split('/').collect();
    let (pkg, sub, ty) = match parts.as_slice() {
        [pkg, ty] => (*pkg, "msg", *ty),
        [pkg, sub, ty] => (*pkg, *sub, *ty),
        _ => bail!("`{name}` is not a message type name (`pkg/msg/Type`)"),
    };
    ensure!(
        is_identifier(pkg) && is_identifier(sub) && is_identifier(ty),
        "`{name}` is not a message type name (`pkg/msg/Type`)"
    );
    Ok(format!("{pkg}/{sub}/{ty}"))
}

/// Every message the schema text defines, by `pkg/msg/Type`, with its fields in order.
fn parse_schema(root: &str, text: &str) -> Result<BTreeMap<String, Fields>> {
    let mut defs = BTreeMap::new();
    let (mut current, mut body) = (root.to_owned(), String::new());
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.len() < 3 || !line.bytes().all(|b| b == b'=') {
            body.push_str(line);
            body.push('\n');
            continue;
        }
        let fields = parse_fields(&current, &body).with_context(|| format!("in `{current}`"))?;
        ensure!(defs.insert(current.clone(), fields).is_none(), "`{current}` is defined twice");
        let header = lines.next().unwrap_or("");
        let dep = header
            .strip_prefix("MSG: ")
            .ok_or_else(|| anyhow!("expected `MSG: pkg/Type` after a separator line, found `{header}`"))?;
        (current, body) = (normalize(dep.trim())?, String::new());
    }
    let fields = parse_fields(&current, &body).with_context(|| format!("in `{current}`"))?;
    ensure!(defs.insert(current.clone(), fields).is_none(), "`{current}` is defined twice");
    Ok(defs)
}

/// The fields of one `.msg` text (constants, comments and default values left out). A message
/// without fields gets rosidl's `uint8 structure_needs_at_least_one_member`.
fn parse_fields(owner: &str, text: &str) -> Result<Fields> {
    let package = owner.split('/').next().unwrap_or("");
    let mut fields = Vec::new();
    for raw in text.lines() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (ty, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let rest = rest.trim_start();
        let end = rest.find(|c: char| c.is_whitespace() || c == '=' || c == '#').unwrap_or(rest.len());
        let (name, after) = (&rest[..end], rest[end..].trim_start());
        ensure!(!name.is_empty(), "`{line}` is not `type name`");
        if after.starts_with('=') {
            continue; // a constant
        }
        ensure!(is_identifier(name), "`{name}` is not a field name");
        let t = field_type(ty, package).with_context(|| format!("field `{name}`"))?;
        fields.push((name.to_owned(), t));
    }
    if fields.is_empty() {
        let t = FieldType { type_id: 3, capacity: 0, string_capacity: 0, nested_type_name: String::new() };
        fields.push(("structure_needs_at_least_one_member".to_owned(), t));
    }
    Ok(fields)
}

fn number(s: &str) -> Result<u64> {
    let n: u64 = s.parse().map_err(|_| anyhow!("`{s}` is not a size"))?;
    ensure!(n > 0, "a size must be positive");
    Ok(n)
}

/// `float64`, `string<=8`, `pkg/Type[4]`, `Header[<=3]`, `uint8[]`, ... as a `FieldType`.
fn field_type(ty: &str, package: &str) -> Result<FieldType> {
    let (base, (increment, capacity)) = match ty.split_once('[') {
        None => (ty, (0, 0)),
        Some((base, rest)) => {
            let inner = rest.strip_suffix(']').ok_or_else(|| anyhow!("`{ty}`: no closing `]`"))?;
            let shape = match inner.strip_prefix("<=") {
                _ if inner.is_empty() => (UNBOUNDED_SEQUENCE, 0),
                Some(n) => (BOUNDED_SEQUENCE, number(n)?),
                None => (ARRAY, number(inner)?),
            };
            (base, shape)
        }
    };
    let mut t = FieldType { type_id: 0, capacity, string_capacity: 0, nested_type_name: String::new() };
    if let Some((s, n)) = base.split_once("<=") {
        t.type_id = match s {
            "string" => BOUNDED_STRING,
            "wstring" => BOUNDED_WSTRING,
            _ => bail!("`{base}`: only strings have a bound"),
        };
        t.string_capacity = number(n)?;
    } else if let Some(id) = primitive_id(base) {
        t.type_id = id;
    } else {
        t.type_id = NESTED;
        t.nested_type_name = match base {
            "Header" => "std_msgs/msg/Header".to_owned(),
            b if b.contains('/') => normalize(b)?,
            b if is_identifier(b) && b.starts_with(|c: char| c.is_ascii_uppercase()) => {
                format!("{package}/msg/{b}")
            }
            b => bail!("unknown type `{b}`"),
        };
    }
    t.type_id += increment;
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_cdr::{Def, Ros2Msg};
    use harvey_msgs::topics;

    /// Each topic's schema and the hash Python `rosbags` 0.11 computes for the schema text the
    /// recording carries (Harvey's `full_text`): the output of `scripts/rihs01_oracle.py`
    /// (`get_types_from_msg` into an empty store, `hash_rihs01`) on the reference recording,
    /// whose 26 schema texts are this build's.
    const ORACLE: &[(&str, &str, &str)] = &[
        (
            "camera/frame",
            "sensor_msgs/msg/Image",
            "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47",
        ),
        (
            "sim/truth",
            "harvey_msgs/msg/TruePose",
            "RIHS01_d13130efd806b742e4626cb4275da4fffa556ed52e9d62e930950d6f57def6c4",
        ),
        (
            "drv/sonar_raw",
            "harvey_msgs/msg/SonarRaw",
            "RIHS01_88c285696a0364df634ddd57d82838c21f46f397ccd44f5f42e2428472859da4",
        ),
        (
            "drv/encoders_raw",
            "harvey_msgs/msg/EncodersRaw",
            "RIHS01_79145ec5e0423a077d6748b0c29ef5935a7c894aaac207c0edad95487f7dbe73",
        ),
        (
            "vehicle/command",
            "harvey_msgs/msg/MotionCommand",
            "RIHS01_c9f20da8734479fc9458b77356fe782da9b9a921e094153028e86a4efc120037",
        ),
        (
            "vehicle/reflex",
            "harvey_msgs/msg/MotionCommand",
            "RIHS01_c9f20da8734479fc9458b77356fe782da9b9a921e094153028e86a4efc120037",
        ),
        (
            "sonar/ring",
            "harvey_msgs/msg/SonarRing",
            "RIHS01_8bde705aed3dbe7f72a792ff0e2320979ab782e3a7df3151e2d9a058585bb914",
        ),
        (
            "odometry",
            "harvey_msgs/msg/Odometry",
            "RIHS01_c5ac44644c9ad4ead8294ac8ea36c8d7fe139cabf0feb940966b21754e62d941",
        ),
        (
            "vision/detections",
            "harvey_msgs/msg/Detections",
            "RIHS01_49e2e5f0269fe97c97161625e1bc34c006debf766b31d356c8d3803a6c7a3c0e",
        ),
        (
            "ums/map",
            "harvey_msgs/msg/UncertaintyMap",
            "RIHS01_c1d1ae73781d1d09deb3f307f3ab50c67b8c0e12565afa3f3d59c6577fccd602",
        ),
        (
            "vision/sightings",
            "harvey_msgs/msg/LandmarkSighting",
            "RIHS01_829dbed80b235672b1efdcb8af3ec366f8be6560bcdcfd744fb9d8626e9e6a97",
        ),
        (
            "ums/expectations",
            "harvey_msgs/msg/Expectation",
            "RIHS01_47c626a1b118e5e835a17fc67ca9c407eeff27ffc0618c1d987e69d48d731d27",
        ),
        (
            "executive/status",
            "harvey_msgs/msg/MissionStatus",
            "RIHS01_5ac41795c002337ef642c70352df8d698f69d37a2bf7ebfcb6cfca702debde23",
        ),
        (
            "executive/servo",
            "harvey_msgs/msg/ServoCorrection",
            "RIHS01_80668c8fe65e6b0a65300480e8baa54562f638842e301e7c0234d0a2653cfe91",
        ),
        (
            "executive/pose",
            "harvey_msgs/msg/PoseFix",
            "RIHS01_443f1137309495884712c7c12f1a12f6d08d23bc6fbaa2c40bd64a1fcd39d5cf",
        ),
        (
            "executive/plan",
            "harvey_msgs/msg/PlanSketch",
            "RIHS01_1b0a49321d94a148adf36e4cb93345249902cd1c89efae7c9248086a172614f1",
        ),
        (
            "executive/behaviour",
            "harvey_msgs/msg/BehaviourState",
            "RIHS01_f65d9a360fac4611f16f5e659b221e254b01f6adf2387b5291a157c88517e44d",
        ),
        (
            "vision/requests",
            "harvey_msgs/msg/VisionRequest",
            "RIHS01_3d35cf7e73694bfaaed4e9289519db3ca083ed9b0e0fd5f571c4f41813295b6a",
        ),
        (
            "vision/results",
            "harvey_msgs/msg/VisionResult",
            "RIHS01_9370b65934d4ccbe0ec7978f3124291e82aa1d09f9d0e779812384d5b146a351",
        ),
        (
            "rosout",
            "rcl_interfaces/msg/Log",
            "RIHS01_e28ce254ca8abc06abf92773b74602cdbf116ed34fbaf294fb9f81da9f318eac",
        ),
        (
            "tf",
            "tf2_msgs/msg/TFMessage",
            "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
        ),
        (
            "tf_static",
            "tf2_msgs/msg/TFMessage",
            "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
        ),
        (
            "markers/map",
            "visualization_msgs/msg/MarkerArray",
            "RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf",
        ),
        (
            "markers/uncertainty",
            "visualization_msgs/msg/MarkerArray",
            "RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf",
        ),
        (
            "markers/plan",
            "visualization_msgs/msg/MarkerArray",
            "RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf",
        ),
        (
            "camera/camera_info",
            "sensor_msgs/msg/CameraInfo",
            "RIHS01_b3dfd68ff46c9d56c80fd3bd4ed22c7a4ddce8c8348f2f59c299e73118e7e275",
        ),
    ];

    /// Stock ROS 2 Jazzy hashes, from rosbags' Jazzy store (`scripts/rihs01_oracle.py`).
    const JAZZY: &[(&str, &str)] = &[
        (
            "builtin_interfaces/msg/Time",
            "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
        ),
        ("std_msgs/msg/Header", "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01"),
        ("std_msgs/msg/String", "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"),
        ("std_msgs/msg/Empty", "RIHS01_20b625256f32d5dbc0d04fee44f43c41e51c70d3502f84b4a08e7a9c26a96312"),
        ("sensor_msgs/msg/Image", "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47"),
        (
            "sensor_msgs/msg/CameraInfo",
            "RIHS01_b3dfd68ff46c9d56c80fd3bd4ed22c7a4ddce8c8348f2f59c299e73118e7e275",
        ),
        ("rcl_interfaces/msg/Log", "RIHS01_e28ce254ca8abc06abf92773b74602cdbf116ed34fbaf294fb9f81da9f318eac"),
        ("tf2_msgs/msg/TFMessage", "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"),
        (
            "visualization_msgs/msg/MarkerArray",
            "RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf",
        ),
    ];

    fn jazzy(name: &str) -> &'static str {
        JAZZY.iter().find(|(n, _)| *n == name).map(|(_, h)| *h).expect("a Jazzy type")
    }

    /// Every topic of `topics::ALL` (the frames' `sensor_msgs/msg/Image` and the log's
    /// `rcl_interfaces/msg/Log` among them), then the recorder's derived topics.
    fn our_topics() -> Vec<(&'static str, &'static Def)> {
        struct Collect(Vec<(&'static str, &'static Def)>);
        impl harvey_recording::topics::TopicVisitor for Collect {
            type Error = std::convert::Infallible;
            fn message<T: harvey_msgs::Message + Ros2Msg>(
                &mut self,
                topic: topics::Topic<T>,
            ) -> Result<(), Self::Error> {
                self.0.push((topic.name, T::DEF));
                Ok(())
            }
        }
        let mut c = Collect(Vec::new());
        let _ = harvey_recording::topics::visit_message_topics(&mut c);
        c.0.push((topics::CAMERA_FRAME.name, harvey_cdr::image_def()));
        assert_eq!(c.0.iter().map(|(t, _)| *t).collect::<Vec<_>>(), topics::ALL);
        for (topic, def, _) in harvey_recording::derive::TOPICS {
            c.0.push((topic, def));
        }
        c.0
    }

    #[test]
    fn every_topic_hashes_as_rosbags_does() {
        let ours = our_topics();
        assert_eq!(ours.len(), ORACLE.len());
        for (topic, def) in ours {
            let (_, schema, hash) = ORACLE.iter().find(|(t, _, _)| *t == topic).expect("an oracle value");
            assert_eq!(def.schema_name(), *schema, "{topic}");
            assert_eq!(rihs01(def).expect("hashes"), *hash, "{topic}");
        }
    }

    #[test]
    fn embedded_standard_types_hash_as_in_jazzy() {
        let image = rihs01(harvey_cdr::image_def()).expect("hashes");
        assert_eq!(image, jazzy("sensor_msgs/msg/Image"));
        assert_eq!(image, "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47");
        let mut standard = 0;
        for (topic, def) in our_topics() {
            if let Some((_, hash)) = JAZZY.iter().find(|(n, _)| *n == def.schema_name()) {
                assert_eq!(rihs01(def).expect("hashes"), *hash, "{topic}");
                standard += 1;
            }
        }
        // camera/frame, rosout, tf, tf_static, three marker topics, camera_info.
        assert_eq!(standard, 8);
        let header = "builtin_interfaces/Time stamp\nstring frame_id\nSEP\n\
                      MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
        let header = header.replace("SEP", &"=".repeat(80));
        assert_eq!(rihs01_of_text("std_msgs/Header", &header).expect("hashes"), jazzy("std_msgs/msg/Header"));
        let time = "int32 sec\nuint32 nanosec\n";
        assert_eq!(
            rihs01_of_text("builtin_interfaces/msg/Time", time).expect("hashes"),
            jazzy("builtin_interfaces/msg/Time")
        );
    }

    #[test]
    fn the_json_hashed_is_rosidls() {
        // rosidl's `calculate_type_hash`: json.dumps, separators ", " and ": ", no defaults.
        assert_eq!(
            description_json("std_msgs/msg/String", "string data\n").expect("parses"),
            "{\"type_description\": {\"type_name\": \"std_msgs/msg/String\", \"fields\": \
             [{\"name\": \"data\", \"type\": {\"type_id\": 17, \"capacity\": 0, \
             \"string_capacity\": 0, \"nested_type_name\": \"\"}}]}, \"referenced_type_descriptions\": []}"
        );
        assert_eq!(
            rihs01_of_text("std_msgs/String", "string data\n").expect("hashes"),
            jazzy("std_msgs/msg/String")
        );
        // A message without fields is given rosidl's placeholder member.
        assert_eq!(rihs01_of_text("std_msgs/msg/Empty", "").expect("hashes"), jazzy("std_msgs/msg/Empty"));
    }

    #[test]
    fn every_field_shape_hashes_as_rosbags_does() {
        // `scripts/rihs01_oracle.py`'s probe: constants (one with `#` in its value), comments,
        // defaults, bounded strings, arrays, bounded and unbounded sequences, nested types by
        // package, by bare name and `Header`.
        let probe = PROBE.replace("SEP", &"=".repeat(80));
        assert_eq!(
            rihs01_of_text("probe_msgs/msg/Probe", &probe).expect("hashes"),
            "RIHS01_ccb8613c534fbe586641d84c6f419b5f75e20eb6cb755985283e34be399d9626"
        );
    }

    const PROBE: &str = "# A probe of every shape
int32 LIMIT=10
string NAME=\"a # b\"
string<=8 name \"x\" # bounded
float64[3] xyz
probe_msgs/Part[<=4] parts
Part one
Header header
uint8[] data
byte b
bool flag true
int8 x
SEP
MSG: probe_msgs/Part
string<=5[2] tags
int16[<=3] small
SEP
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
SEP
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
";

    #[test]
    fn char_and_wstring_take_rosidls_ids() {
        // rosidl_adapter makes a .msg `char` an IDL `uint8` (rosbags says FIELD_TYPE_CHAR, 13).
        let json = |text: &str| description_json("p/msg/T", text).expect("parses");
        assert_eq!(json("char c\n"), json("uint8 c\n"));
        let w = json("wstring a\nwstring<=3 b\nwstring[2] c\n");
        for id in [
            "\"type_id\": 18, \"capacity\": 0, \"string_capacity\": 0",
            "\"type_id\": 22, \"capacity\": 0, \"string_capacity\": 3",
            "\"type_id\": 66, \"capacity\": 2",
        ] {
            assert!(w.contains(id), "{id} in {w}");
        }
    }

    #[test]
    fn bad_schemas_are_named() {
        let err = |name: &str, text: &str| format!("{:#}", rihs01_of_text(name, text).expect_err("refused"));
        assert!(err("p/msg/T", "p/Missing m\n").contains("`p/msg/Missing` is used but not defined"));
        assert!(err("p/msg/T", "int32[0] a\n").contains("a size must be positive"));
        assert!(err("p/msg/T", "int32[x] a\n").contains("`x` is not a size"));
        assert!(err("p/msg/T", "float a\n").contains("unknown type `float`"));
        assert!(err("p/msg/T", "int32\n").contains("`int32` is not `type name`"));
        assert!(err("p/msg/T", "int32<=3 a\n").contains("only strings have a bound"));
        assert!(err("p/msg/T", "int32 a\n===\nint32 b\n").contains("expected `MSG: pkg/Type`"));
        assert!(err("T", "int32 a\n").contains("`T` is not a message type name"));
    }
}
