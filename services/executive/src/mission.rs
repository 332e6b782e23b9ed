//! The mission a launch file gives the executive: a script of TURN and MOVE primitives with a
//! time limit. Plan-and-monitor over the locale graph replaces the script in its own issue.

use serde::Deserialize;

/// One primitive: exactly one of its fields is set.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    pub move_m: Option<f64>,
    pub turn_deg: Option<f64>,
}

/// The `[mission]` table of a launch file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mission {
    pub description: String,
    /// Simulated seconds before the mission counts as failed.
    pub timeout_s: f64,
    #[serde(rename = "step")]
    pub steps: Vec<Step>,
}

#[derive(Deserialize)]
struct File {
    mission: Option<Mission>,
}

/// Reads the `[mission]` table of a launch file; other tables belong to the supervisor.
pub fn parse(text: &str, file: &str) -> Result<Mission, String> {
    let doc: toml::Table = toml::from_str(text).map_err(|e| format!("{file}: {}", e.message()))?;
    let only_mission: toml::Table = doc.into_iter().filter(|(k, _)| k == "mission").collect();
    let parsed: File = serde_path_to_error::deserialize(only_mission)
        .map_err(|e| format!("{file}: field `{}`: {}", e.path(), e.inner().message()))?;
    let m = parsed.mission.ok_or_else(|| format!("{file}: no [mission] table"))?;
    if !greater(m.timeout_s, 0.0) {
        return Err(format!("{file}: mission.timeout_s must be positive"));
    }
    if m.steps.is_empty() {
        return Err(format!("{file}: the mission has no [[mission.step]]"));
    }
    for (i, s) in m.steps.iter().enumerate() {
        match (s.move_m, s.turn_deg) {
            (Some(v), None) | (None, Some(v)) if v.is_finite() => {}
            _ => {
                return Err(format!(
                    "{file}: mission.step[{i}] needs exactly one finite `move_m` or `turn_deg`"
                ));
            }
        }
    }
    Ok(m)
}

/// `v > min`, false for NaN: the check that a number is usable.
fn greater(v: f64, min: f64) -> bool {
    v > min
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mission_table_is_read_and_checked() {
        let text = "[launch]\nname = \"x\"\n[mission]\ndescription = \"d\"\ntimeout_s = 60\n[[mission.step]]\nmove_m = 2.0\n[[mission.step]]\nturn_deg = 90\n";
        let m = parse(text, "m.toml").expect("parses");
        assert_eq!(
            m.steps,
            vec![Step { move_m: Some(2.0), turn_deg: None }, Step { move_m: None, turn_deg: Some(90.0) }]
        );
        let both = text.replace("turn_deg = 90", "turn_deg = 90\nmove_m = 1");
        assert!(parse(&both, "m.toml").expect_err("two fields").contains("mission.step[1]"));
        let typo = text.replace("timeout_s", "timeout");
        assert!(parse(&typo, "m.toml").expect_err("unknown field").contains("m.toml: field `mission"));
    }
}
