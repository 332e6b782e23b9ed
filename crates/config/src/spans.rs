//! Where each key of a TOML file is: the text parsed a second time into a tree of spans, looked
//! up by a key path (`wall[3].region[1].reflectance`) to name the line of a refused value. Only
//! built when a value is refused, so a good file is parsed once.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};

/// One step of a key path: a table's key or an array's index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    Key(&'static str),
    /// A key chosen by the file (a terrain's name).
    Name(String),
    Index(usize),
}

/// A key path, shown as the file spells it: `terrain.tile.drift_deg_per_ft`, `wall[0].from[1]`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct KeyPath(pub Vec<Step>);

impl KeyPath {
    /// This path, one step further.
    pub fn then(&self, step: Step) -> KeyPath {
        let mut steps = self.0.clone();
        steps.push(step);
        KeyPath(steps)
    }

    pub fn key(&self, key: &'static str) -> KeyPath {
        self.then(Step::Key(key))
    }

    pub fn index(&self, i: usize) -> KeyPath {
        self.then(Step::Index(i))
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.0.iter().enumerate() {
            match s {
                Step::Key(k) if i == 0 => write!(f, "{k}")?,
                Step::Name(k) if i == 0 => write!(f, "{k}")?,
                Step::Key(k) => write!(f, ".{k}")?,
                Step::Name(k) => write!(f, ".{k}")?,
                Step::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// A value of the file with the places of what it holds.
enum Node {
    Leaf,
    Table(BTreeMap<String, Located>),
    Array(Vec<Located>),
}

/// A value and where it starts: [`toml::Spanned`], except that a table the file only implies (the
/// `terrain` of `[terrain.tile]`) has no place rather than failing the parse.
struct Located {
    start: Option<usize>,
    node: Node,
}

/// The names by which the TOML deserializer hands out spans (`serde_spanned`'s protocol).
const SPANNED: &str = "$__serde_spanned_private_Spanned";
const START: &str = "$__serde_spanned_private_start";
const END: &str = "$__serde_spanned_private_end";
const VALUE: &str = "$__serde_spanned_private_value";

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(NodeVisitor)
    }
}

impl<'de> Deserialize<'de> for Located {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_struct(SPANNED, &[START, END, VALUE], LocatedVisitor)
    }
}

struct NodeVisitor;

impl<'de> Visitor<'de> for NodeVisitor {
    type Value = Node;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any TOML value")
    }
    fn visit_bool<E>(self, _: bool) -> Result<Node, E> {
        Ok(Node::Leaf)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Node, E> {
        Ok(Node::Leaf)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Node, E> {
        Ok(Node::Leaf)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Node, E> {
        Ok(Node::Leaf)
    }
    fn visit_str<E>(self, _: &str) -> Result<Node, E> {
        Ok(Node::Leaf)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Node, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element::<Located>()? {
            items.push(item);
        }
        Ok(Node::Array(items))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Node, A::Error> {
        let mut table = BTreeMap::new();
        while let Some((k, v)) = map.next_entry::<String, Located>()? {
            table.insert(k, v);
        }
        Ok(Node::Table(table))
    }
}

struct LocatedVisitor;

/// A scalar the deserializer gave no place.
const LEAF: Located = Located { start: None, node: Node::Leaf };

impl<'de> Visitor<'de> for LocatedVisitor {
    type Value = Located;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any TOML value")
    }
    fn visit_bool<E>(self, _: bool) -> Result<Located, E> {
        Ok(LEAF)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Located, E> {
        Ok(LEAF)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Located, E> {
        Ok(LEAF)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Located, E> {
        Ok(LEAF)
    }
    fn visit_str<E>(self, _: &str) -> Result<Located, E> {
        Ok(LEAF)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Located, A::Error> {
        Ok(Located { start: None, node: NodeVisitor.visit_seq(seq)? })
    }
    /// Either the span protocol (start, end, value) or a table without a place.
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Located, A::Error> {
        let (mut table, mut start, mut node) = (BTreeMap::new(), None, None);
        while let Some(k) = map.next_key::<String>()? {
            match k.as_str() {
                START => start = Some(map.next_value::<usize>()?),
                END => {
                    map.next_value::<serde::de::IgnoredAny>()?;
                }
                VALUE => node = Some(map.next_value::<Node>()?),
                _ => {
                    table.insert(k, map.next_value::<Located>()?);
                }
            }
        }
        Ok(Located { start, node: node.unwrap_or(Node::Table(table)) })
    }
}

/// The 1-based line at byte `offset` of `text`.
pub fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// The line of the value at `path` in `text`; if the path goes further than the file (a value
/// left to its default), the line of the deepest part of it that is there; 0 if none is.
pub fn line_of_key(text: &str, path: &KeyPath) -> usize {
    let Ok(root) = toml::from_str::<Node>(text) else { return 0 };
    let mut node = &root;
    let mut at = None;
    for step in &path.0 {
        let next = match (node, step) {
            (Node::Table(t), Step::Key(k)) => t.get(*k),
            (Node::Table(t), Step::Name(k)) => t.get(k),
            (Node::Array(a), Step::Index(i)) => a.get(*i),
            _ => None,
        };
        let Some(next) = next else { break };
        at = next.start.or(at);
        node = &next.node;
    }
    at.map_or(0, |offset| line_of(text, offset))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_found_down_to_array_elements() {
        let text = "a = 1\n[b]\nc = [1.0,\n  2.0]\n[[d]]\nx = 1\n[[d]]\nx = 2\n[[d.e]]\ny = 3\n";
        let path = |steps: Vec<Step>| KeyPath(steps);
        use Step::{Index, Key};
        assert_eq!(line_of_key(text, &path(vec![Key("a")])), 1);
        assert_eq!(line_of_key(text, &path(vec![Key("b"), Key("c"), Index(1)])), 4);
        assert_eq!(line_of_key(text, &path(vec![Key("d"), Index(1), Key("x")])), 8);
        assert_eq!(line_of_key(text, &path(vec![Key("d"), Index(1), Key("e"), Index(0), Key("y")])), 10);
        // Missing at the end: the deepest part that is there.
        assert_eq!(line_of_key(text, &path(vec![Key("d"), Index(0), Key("zz")])), 5);
        let shown = path(vec![Key("wall"), Index(3), Key("from"), Index(1)]).to_string();
        assert_eq!(shown, "wall[3].from[1]");
        assert_eq!(line_of_key("not toml = = =", &path(vec![Key("a")])), 0);
        // A table the file only implies has no line of its own: its keys have.
        let implied = "[t.u]\nx = 1\n\n[t.v]\ny = 2\n";
        assert_eq!(line_of_key(implied, &path(vec![Key("t"), Step::Name("v".into()), Key("y")])), 5);
    }
}
