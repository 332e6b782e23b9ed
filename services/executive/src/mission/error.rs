//! Why a launch file's `[mission]` table was refused: each error names the file and the key.

/// A `[mission]` table that cannot be run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MissionError {
    /// Not TOML at all.
    #[error("{file}: {message}")]
    Toml { file: String, message: String },
    /// A field of the wrong type, missing or unknown.
    #[error("{file}: field `{path}`: {message}")]
    Field { file: String, path: String, message: String },
    #[error("{file}: no [mission] table")]
    NoMission { file: String },
    /// A number outside its range, or a list longer than its cap (`bounds.rs`): the key as the
    /// file spells it, and the line where the file gives it (0 when it is left to its default).
    #[error("{file}:{line}: key `{key}`: {detail}")]
    OutOfRange { file: String, line: usize, key: String, detail: String },
    #[error("{file}: mission.timeout_s must be positive")]
    Timeout { file: String },
    #[error(
        "{file}: the mission has no [[mission.step]], [mission.ptrans], [mission.docking], [mission.poles], \
         [mission.neptune] or [mission.door]"
    )]
    NothingToDo { file: String },
    #[error(
        "{file}: [mission.ptrans], [mission.docking], [mission.poles], [mission.neptune] and [mission.door] \
         make their own steps: one of them, and no [[mission.step]]"
    )]
    TooMuchToDo { file: String },
    /// A goal table (`ptrans`, `docking` or `poles`) whose values do not make sense.
    #[error("{file}: mission.{table}: {what}")]
    Goal { file: String, table: &'static str, what: &'static str },
    #[error(
        "{file}: mission.step[{index}] needs exactly one finite `move_m` or `turn_deg`, or \
         `refine_pose` with two or more [mission.refine] vertices_m or its select_contrast"
    )]
    Step { file: String, index: usize },
    #[error("{file}: mission.step[{index}].increment_m must be positive, on a move")]
    Increment { file: String, index: usize },
    #[error("{file}: mission.step[{index}].servo_landmark needs `increment_m` and a [mission.servo] table")]
    ServoLandmark { file: String, index: usize },
    #[error("{file}: mission.servo: aim_m must be positive, template_px at least 4")]
    Servo { file: String },
}
