//! `ros2msg` schema texts: a message's own `.msg` text followed by its dependencies' texts, each
//! after a line of 80 `=` and `MSG: pkg/Type`, depth first, sorted, without repeats (as rosbag2
//! writes them).

/// A message definition: its name as written in fields (`std_msgs/Header`), its `.msg` text
/// (ending in a newline) and the definitions its fields use.
#[derive(Debug)]
pub struct Def {
    pub name: &'static str,
    pub text: &'static str,
    pub deps: &'static [&'static Def],
}

impl Def {
    /// The schema name MCAP's ROS 2 profile wants: `pkg/msg/Type`.
    pub fn schema_name(&self) -> String {
        match self.name.split_once('/') {
            Some((pkg, ty)) => format!("{pkg}/msg/{ty}"),
            None => self.name.to_owned(),
        }
    }
}

/// The complete schema data of `def`.
pub fn full_text(def: &Def) -> String {
    fn append(def: &Def, out: &mut String, seen: &mut Vec<&'static str>) {
        let mut deps: Vec<&Def> = def.deps.to_vec();
        deps.sort_by(|a, b| a.name.as_bytes().cmp(b.name.as_bytes()));
        for d in deps {
            if seen.contains(&d.name) {
                continue;
            }
            seen.push(d.name);
            out.push('\n');
            out.push_str(&"=".repeat(80));
            out.push_str("\nMSG: ");
            out.push_str(d.name);
            out.push('\n');
            out.push_str(d.text);
            append(d, out, seen);
        }
    }
    let mut out = def.text.to_owned();
    append(def, &mut out, &mut Vec::new());
    out
}
