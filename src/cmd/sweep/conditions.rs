//! Sensor conditions for `harvey sweep`: a condition is a TOML file of world-table overrides
//! (`[camera] noise_sd = 8`), named by a path or by a name of `conditions/`. Its tables are merged
//! into the mission's world, and the merged world must pass the world loader; a refusal names
//! the condition file, the line and the key.

use std::path::{Path, PathBuf};

/// A condition that cannot be used, with where and why.
#[derive(Debug, thiserror::Error)]
pub enum ConditionError {
    #[error("{file}: {detail}")]
    Io { file: String, detail: String },
    /// A key of the condition file that is not a world field, or a value outside its range.
    #[error("{file}:{line}: key `{key}`: {detail}")]
    Key { file: String, line: usize, key: String, detail: String },
    /// The world refused for a reason the condition does not name (the world's own fault).
    #[error("{world} with condition {file}: {detail}")]
    World { file: String, world: String, detail: String },
    #[error("no condition `{name}`: neither a file nor one of {searched}")]
    Unknown { name: String, searched: String },
}

/// A loaded condition: its name (the file's stem), file and override tables.
#[derive(Debug, Clone)]
pub struct Condition {
    pub name: String,
    pub file: PathBuf,
    text: String,
    overrides: toml::Table,
}

/// Where a condition named `name` is looked for: a path as given, else `conditions/NAME.toml`
/// in the current folder, else next to the mission's folder (`missions/../conditions`).
pub fn resolve(name: &str, mission: &Path) -> Result<PathBuf, ConditionError> {
    let given = PathBuf::from(name);
    if given.is_file() || name.contains('/') || name.ends_with(".toml") {
        return Ok(given);
    }
    let file = format!("{name}.toml");
    let mut searched = vec![Path::new("conditions").join(&file)];
    if let Some(dir) = mission.parent().and_then(Path::parent) {
        searched.push(dir.join("conditions").join(&file));
    }
    searched.iter().find(|p| p.is_file()).cloned().ok_or_else(|| ConditionError::Unknown {
        name: name.to_owned(),
        searched: searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "),
    })
}

impl Condition {
    pub fn load(file: &Path) -> Result<Self, ConditionError> {
        let text = std::fs::read_to_string(file).map_err(|e| ConditionError::Io {
            file: file.display().to_string(),
            detail: format!("cannot read: {e}"),
        })?;
        Self::parse(&text, file)
    }

    pub fn parse(text: &str, file: &Path) -> Result<Self, ConditionError> {
        let shown = file.display().to_string();
        let overrides: toml::Table = toml::from_str(text).map_err(|e| ConditionError::Key {
            file: shown.clone(),
            line: e.span().map_or(0, |s| line_of(text, s.start)),
            key: "-".into(),
            detail: e.message().to_owned(),
        })?;
        let name = file.file_stem().map_or_else(|| shown.clone(), |s| s.to_string_lossy().into_owned());
        Ok(Self { name, file: file.to_owned(), text: text.to_owned(), overrides })
    }

    /// Whether the condition changes nothing (the world as its file gives it).
    pub fn is_empty(&self) -> bool {
        self.overrides.is_empty()
    }

    /// The world text `world_text` (of file `world_file`) with this condition's overrides, checked
    /// by the world loader. Without overrides, the world's own text, unchanged.
    pub fn apply(&self, world_text: &str, world_file: &str) -> Result<String, ConditionError> {
        let file = self.file.display().to_string();
        let merged = if self.is_empty() {
            world_text.to_owned()
        } else {
            let mut world: toml::Table = toml::from_str(world_text).map_err(|e| ConditionError::World {
                file: file.clone(),
                world: world_file.to_owned(),
                detail: e.to_string(),
            })?;
            merge(&mut world, &self.overrides);
            toml::to_string(&world).map_err(|e| ConditionError::World {
                file: file.clone(),
                world: world_file.to_owned(),
                detail: e.to_string(),
            })?
        };
        let refused = |field: &str, detail: String| match line_of_key(&self.text, field) {
            Some(line) => ConditionError::Key { file: file.clone(), line, key: field.to_owned(), detail },
            None => ConditionError::World { file: file.clone(), world: world_file.to_owned(), detail },
        };
        match harvey_world::load_str(&merged, world_file) {
            Ok(_) => Ok(merged),
            Err(harvey_world::WorldError::Parse { field, detail, .. }) => Err(refused(&field, detail)),
            Err(harvey_world::WorldError::OutOfRange { field, detail, .. }) => Err(refused(&field, detail)),
            Err(e) => {
                Err(ConditionError::World { file, world: world_file.to_owned(), detail: e.to_string() })
            }
        }
    }
}

/// Merges `over` into `base`: tables key by key, any other value replaces the base's.
fn merge(base: &mut toml::Table, over: &toml::Table) {
    for (k, v) in over {
        match (base.get_mut(k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            _ => {
                base.insert(k.clone(), v.clone());
            }
        }
    }
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// The line of `text` that sets key path `field` (`camera.noise_sd`; array indices ignored), or
/// that opens its table; `None` if the file names it nowhere.
fn line_of_key(text: &str, field: &str) -> Option<usize> {
    let want = strip_indices(field);
    let mut table = String::new();
    let mut opens = None;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let path = if let Some(h) = line.strip_prefix('[') {
            table = plain_key(h.trim_start_matches('[').trim_end_matches(']'));
            table.clone()
        } else if let Some((k, _)) = line.split_once('=') {
            let k = plain_key(k);
            if table.is_empty() { k } else { format!("{table}.{k}") }
        } else {
            continue;
        };
        if path == want {
            return Some(i + 1);
        }
        if opens.is_none() && want.starts_with(&format!("{path}.")) {
            opens = Some(i + 1);
        }
    }
    opens
}

/// A key as written (`"a" . b`) as a dotted path (`a.b`).
fn plain_key(k: &str) -> String {
    k.split('.').map(|p| p.trim().trim_matches('"').trim_matches('\'')).collect::<Vec<_>>().join(".")
}

fn strip_indices(field: &str) -> String {
    let mut out = String::new();
    let mut depth = 0;
    for c in field.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            _ if depth == 0 => out.push(c),
            _ => {}
        }
    }
    out
}

#[cfg(test)]
#[path = "conditions_tests.rs"]
mod tests;
