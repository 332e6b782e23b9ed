//! Decoding CDR by a `ros2msg` schema text alone, into JSON values: what a tool that does not
//! know a message's Rust type (`harvey topic echo`, a recording's message of another program)
//! reads it with. The schema is the full text the recorder writes (the message's own definition,
//! then each dependency after a line of `=` and `MSG: pkg/Type`).

use std::collections::BTreeMap;

use serde_json::{Map, Number, Value};

use crate::codec::{CdrError, CdrReader};

/// Nested messages deeper than this are refused (a schema that refers to itself).
const MAX_DEPTH: usize = 32;

/// Why a schema text cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("schema {name}, line {line}: {what}")]
pub struct SchemaError {
    pub name: String,
    pub line: usize,
    pub what: String,
}

#[derive(Debug, Clone, PartialEq)]
enum Base {
    Bool,
    Int(u8),
    UInt(u8),
    Float32,
    Float64,
    Str,
    Msg(String),
}

#[derive(Debug, Clone, PartialEq)]
enum Shape {
    One,
    Fixed(usize),
    Seq,
}

#[derive(Debug, Clone, PartialEq)]
struct Field {
    name: String,
    base: Base,
    shape: Shape,
}

/// A message definition with its dependencies, ready to decode with.
#[derive(Debug, Clone)]
pub struct Schema {
    root: String,
    defs: BTreeMap<String, Vec<Field>>,
}

/// `pkg/msg/Type` and `pkg/Type` name the same message.
fn canonical(name: &str) -> String {
    match name.split('/').collect::<Vec<_>>().as_slice() {
        [pkg, "msg", ty] => format!("{pkg}/{ty}"),
        _ => name.to_owned(),
    }
}

fn base(ty: &str, package: &str) -> Result<Base, String> {
    let ty = ty.split("<=").next().unwrap_or(ty);
    Ok(match ty {
        "bool" => Base::Bool,
        "byte" | "uint8" | "char" => Base::UInt(1),
        "int8" => Base::Int(1),
        "int16" => Base::Int(2),
        "uint16" => Base::UInt(2),
        "int32" => Base::Int(4),
        "uint32" => Base::UInt(4),
        "int64" => Base::Int(8),
        "uint64" => Base::UInt(8),
        "float32" => Base::Float32,
        "float64" => Base::Float64,
        "string" => Base::Str,
        "wstring" => return Err("wstring is not supported".into()),
        "Header" => Base::Msg("std_msgs/Header".into()),
        t if t.contains('/') => Base::Msg(canonical(t)),
        t if t.chars().next().is_some_and(|c| c.is_ascii_uppercase()) => Base::Msg(format!("{package}/{t}")),
        t => return Err(format!("unknown type `{t}`")),
    })
}

fn parse_fields(name: &str, text: &str, first_line: usize) -> Result<Vec<Field>, SchemaError> {
    let package = name.split('/').next().unwrap_or("");
    let mut fields = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let err = |what: String| SchemaError { name: name.to_owned(), line: first_line + k, what };
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut words = line.split_whitespace();
        let (Some(ty), Some(field)) = (words.next(), words.next()) else {
            return Err(err(format!("`{line}` is not `type name`")));
        };
        if field.contains('=') || words.next().is_some_and(|w| w.starts_with('=')) {
            continue; // a constant
        }
        let (ty, shape) = match ty.split_once('[') {
            None => (ty, Shape::One),
            Some((t, rest)) => {
                let n = rest.trim_end_matches(']');
                match n {
                    "" => (t, Shape::Seq),
                    n if n.starts_with("<=") => (t, Shape::Seq),
                    n => (t, Shape::Fixed(n.parse().map_err(|_| err(format!("bad array size `{n}`")))?)),
                }
            }
        };
        fields.push(Field { name: field.to_owned(), base: base(ty, package).map_err(err)?, shape });
    }
    if fields.is_empty() {
        return Err(SchemaError { name: name.to_owned(), line: first_line, what: "no fields".into() });
    }
    Ok(fields)
}

impl Schema {
    /// Parses the full schema text of message `name` (`pkg/msg/Type` or `pkg/Type`).
    pub fn parse(name: &str, text: &str) -> Result<Self, SchemaError> {
        let root = canonical(name);
        let mut defs = BTreeMap::new();
        let (mut current, mut body, mut first) = (root.clone(), String::new(), 1);
        let mut lines = text.lines().enumerate().peekable();
        while let Some((k, line)) = lines.next() {
            let separator = line.len() >= 3 && line.bytes().all(|b| b == b'=');
            if !separator {
                body.push_str(line);
                body.push('\n');
                continue;
            }
            defs.insert(current.clone(), parse_fields(&current, &body, first)?);
            let Some((_, msg)) = lines.next() else { break };
            let Some(dep) = msg.strip_prefix("MSG: ") else {
                let what = format!("expected `MSG: pkg/Type` after the separator, found `{msg}`");
                return Err(SchemaError { name: root, line: k + 2, what });
            };
            (current, body, first) = (canonical(dep.trim()), String::new(), k + 3);
        }
        if !body.trim().is_empty() || !defs.contains_key(&current) {
            defs.insert(current.clone(), parse_fields(&current, &body, first)?);
        }
        let schema = Self { root, defs };
        schema.check(&schema.root, 0)?;
        Ok(schema)
    }

    /// Every nested type is defined, and nesting ends.
    fn check(&self, name: &str, depth: usize) -> Result<(), SchemaError> {
        let err = |what: String| SchemaError { name: name.to_owned(), line: 0, what };
        if depth > MAX_DEPTH {
            return Err(err(format!("nested more than {MAX_DEPTH} deep")));
        }
        let fields = self.defs.get(name).ok_or_else(|| err(format!("`{name}` is not defined")))?;
        for f in fields {
            if let Base::Msg(m) = &f.base {
                self.check(m, depth + 1)?;
            }
        }
        Ok(())
    }

    /// Decodes one CDR message (with its encapsulation header) into a JSON object.
    pub fn decode(&self, data: &[u8]) -> Result<Value, CdrError> {
        let mut r = CdrReader::new(data)?;
        self.message(&self.root, &mut r)
    }

    fn message(&self, name: &str, r: &mut CdrReader<'_>) -> Result<Value, CdrError> {
        let mut out = Map::new();
        for f in self.defs.get(name).map_or(&[][..], Vec::as_slice) {
            let v = match f.shape {
                Shape::One => self.one(&f.base, r)?,
                Shape::Fixed(n) => {
                    Value::Array((0..n).map(|_| self.one(&f.base, r)).collect::<Result<_, _>>()?)
                }
                Shape::Seq => {
                    let at = r.offset();
                    let n = r.prim::<u32>()? as usize;
                    if n > r.remaining() {
                        let what = format!("a sequence of {n} for {} bytes left", r.remaining());
                        return Err(CdrError::Invalid { at, what });
                    }
                    Value::Array((0..n).map(|_| self.one(&f.base, r)).collect::<Result<_, _>>()?)
                }
            };
            out.insert(f.name.clone(), v);
        }
        Ok(Value::Object(out))
    }

    fn one(&self, base: &Base, r: &mut CdrReader<'_>) -> Result<Value, CdrError> {
        let float = |x: f64| Number::from_f64(x).map_or(Value::String(x.to_string()), Value::Number);
        Ok(match base {
            Base::Bool => Value::Bool(r.prim::<u8>()? != 0),
            Base::Int(1) => Value::from(r.prim::<i8>()?),
            Base::Int(2) => Value::from(r.prim::<i16>()?),
            Base::Int(4) => Value::from(r.prim::<i32>()?),
            Base::Int(_) => Value::from(r.prim::<i64>()?),
            Base::UInt(1) => Value::from(r.prim::<u8>()?),
            Base::UInt(2) => Value::from(r.prim::<u16>()?),
            Base::UInt(4) => Value::from(r.prim::<u32>()?),
            Base::UInt(_) => Value::from(r.prim::<u64>()?),
            Base::Float32 => float(f64::from(r.prim::<f32>()?)),
            Base::Float64 => float(r.prim::<f64>()?),
            Base::Str => Value::String(r.string()?),
            Base::Msg(m) => self.message(m, r)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Ros2Msg, encode, full_text};
    use harvey_msgs::{Header, LogLevel, LogLine, Pose2, UncertaintyMap};

    fn schema_of<T: Ros2Msg>() -> Schema {
        Schema::parse(&T::DEF.schema_name(), &full_text(T::DEF)).expect("parses")
    }

    #[test]
    fn harvey_messages_decode_by_their_schema_text_alone() {
        let mut map = UncertaintyMap {
            header: Header::new(7, 1_500_000_000),
            centre: Pose2 { x_m: 1.0, y_m: -2.0, heading_rad: 0.5 },
            vertex_count: 3,
            area_m2: 0.25,
            ..Default::default()
        };
        map.vertices_m[0] = [0.5, 4.5];
        let v = schema_of::<UncertaintyMap>().decode(&encode(&map, Vec::new())).expect("decodes");
        assert_eq!(v["header"]["stamp"]["sec"], 1);
        assert_eq!(v["header"]["stamp"]["nanosec"], 500_000_000);
        assert_eq!(v["seq"], 7);
        assert_eq!(v["centre"]["y_m"], -2.0);
        assert_eq!(v["vertex_count"], 3);
        assert_eq!(v["vertices_m"].as_array().map(Vec::len), Some(64));
        assert_eq!(v["vertices_m"][1], 4.5);
        assert_eq!(v["area_m2"], 0.25);

        let line = LogLine::new(Header::new(0, 2_000_000_000), LogLevel::Warn, "ums", "rejected");
        let v = schema_of::<LogLine>().decode(&encode(&line, Vec::new())).expect("decodes");
        assert_eq!(
            (v["level"].as_u64(), v["name"].as_str(), v["msg"].as_str()),
            (Some(30), Some("ums"), Some("rejected"))
        );
    }

    #[test]
    fn bad_schemas_and_short_data_are_errors_not_panics() {
        let e = Schema::parse("p/msg/A", "int32 a\nfoo b\n").expect_err("unknown type");
        assert_eq!(e.to_string(), "schema p/A, line 2: unknown type `foo`");
        let e = Schema::parse("p/A", "p/B b\n").expect_err("undefined");
        assert!(e.to_string().contains("`p/B` is not defined"), "{e}");
        let e =
            Schema::parse("p/A", &format!("A a\n{}\nMSG: p/A\nA a\n", "=".repeat(80))).expect_err("cycle");
        assert!(e.to_string().contains("nested more than"), "{e}");
        let s = Schema::parse("p/A", "uint8 K=3\nuint32[] xs\n").expect("a constant is skipped");
        // A sequence claiming more elements than there are bytes.
        let data = [0, 1, 0, 0, 0xff, 0xff, 0xff, 0x0f];
        assert!(s.decode(&data).is_err());
        assert!(s.decode(&[0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0]).is_err(), "one element short");
        let v = s.decode(&[0, 1, 0, 0, 1, 0, 0, 0, 9, 0, 0, 0]).expect("one element");
        assert_eq!(v["xs"], serde_json::json!([9]));
    }
}
