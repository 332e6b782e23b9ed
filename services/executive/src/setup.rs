//! Building an executive from a launch file's `[mission]` and the world: each step's landmark
//! servoing, the vertices plan-level servoing anchors on landmarks, the plan's goal locale, the
//! behaviours' acceptors (files next to the launch file) and camera. Errors name the mission
//! file and the key whose value the world or the acceptor cannot satisfy.

use std::path::{Path, PathBuf};

use harvey_world::{World, WorldError};

use crate::behaviours::Run;
use crate::behaviours::fsa::FsaError;
use crate::mission::{self, Mission, MissionError};
use crate::plan::Plan;
use crate::plan::monitor::Monitor;
use crate::script::Script;
use crate::script::leg::ServoSetup;
use crate::servo::ServoParams;
use crate::servo::pose::{PinholeCamera, RefineParams};
use crate::servo::vertices::{Growth, RefineSetup};
use crate::{Executive, Mode};

/// Why no executive could be built for a mission.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    #[error("reading {}: {source}", path.display())]
    Read { path: PathBuf, source: std::io::Error },
    #[error(transparent)]
    Mission(#[from] MissionError),
    #[error(transparent)]
    World(#[from] WorldError),
    /// `key` needs the world, and none was given.
    #[error("{file}: {key} needs the world: pass --world")]
    NoWorld { file: String, key: String },
    #[error("{file}: {key}: no landmark {landmark} in world {world}")]
    NoLandmark { file: String, key: String, landmark: String, world: String },
    #[error("{file}: mission.refine: world {world} has no landmark to anchor vertices on")]
    NoAnchor { file: String, world: String },
    /// Listed and selected, fewer than two vertices to refine a pose from.
    #[error("{file}: mission.refine: {count} vertices listed and selected; a pose fix needs at least 2")]
    FewVertices { file: String, count: usize },
    #[error("{file}: mission.ptrans.to: locale {locale}, which world {world} lacks")]
    NoLocale { file: String, locale: String, world: String },
    #[error("{file}: mission.poles: world {world} has no [poles]")]
    NoPoles { file: String, world: String },
    /// The acceptor file `key` names cannot be read.
    #[error("{file}: {key}: reading {}: {source}", path.display())]
    ReadAcceptor { file: String, key: String, path: PathBuf, source: std::io::Error },
    #[error("{file}: {key}: {source}")]
    Acceptor { file: String, key: String, source: FsaError },
    /// The acceptor has no state of the name `key` gives.
    #[error("{file}: {key}: acceptor {acceptor} has no state {state}")]
    NoState { file: String, key: String, acceptor: String, state: String },
}

/// The mission file read and parsed, the world loaded, and the executive built from them.
#[derive(Debug)]
pub struct Loaded {
    pub mission: Mission,
    pub world: Option<World>,
    pub executive: Executive,
}

/// Reads the launch file's `[mission]` and the world file, and builds the executive; `seed` is
/// the noise schema's.
pub fn load(mission_file: &Path, world_file: Option<&Path>, seed: u64) -> Result<Loaded, SetupError> {
    let text = std::fs::read_to_string(mission_file)
        .map_err(|source| SetupError::Read { path: mission_file.to_owned(), source })?;
    let mission = mission::parse(&text, &mission_file.display().to_string())?;
    let world = world_file.map(World::load).transpose()?;
    let executive = executive(&mission, mission_file, world.as_ref(), seed)?;
    Ok(Loaded { mission, world, executive })
}

/// The executive for `mission`, read from `mission_file` (its acceptors are found next to it),
/// in `world`.
pub fn executive(
    mission: &Mission,
    mission_file: &Path,
    world: Option<&World>,
    seed: u64,
) -> Result<Executive, SetupError> {
    let at = Site { mission, file: mission_file, world };
    let servo = at.servo_setups()?;
    let refine = at.refine_setup()?;
    let monitor = at.monitor()?;
    let behaviour = at.behaviour(seed)?;
    let mut script = Script::new(mission.steps.clone(), mission.servo, servo);
    if let Some(setup) = refine {
        script = script.with_refine(setup);
    }
    let mode = match (behaviour, monitor) {
        (Some(b), _) => Mode::Sequenced(Run::new(b)),
        (None, Some(m)) => Mode::Plan(Box::new(Plan::new(script, m))),
        (None, None) => Mode::Script(Box::new(script)),
    };
    Ok(Executive::new(mode, mission.timeout_s))
}

/// What the set-up reads from.
struct Site<'a> {
    mission: &'a Mission,
    file: &'a Path,
    world: Option<&'a World>,
}

impl Site<'_> {
    fn name(&self) -> String {
        self.file.display().to_string()
    }

    /// The world, which `key` needs.
    fn world(&self, key: &str) -> Result<&World, SetupError> {
        self.world.ok_or_else(|| SetupError::NoWorld { file: self.name(), key: key.to_owned() })
    }

    /// How each step servos: its landmark looked up in the world, the camera from its calibration.
    fn servo_setups(&self) -> Result<Vec<Option<ServoSetup>>, SetupError> {
        let m = self.mission;
        m.steps
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let (Some(name), Some(sv)) = (&s.servo_landmark, m.servo) else { return Ok(None) };
                let key = format!("mission.step[{i}].servo_landmark");
                let w = self.world(&key)?;
                let (index, l) =
                    w.landmarks.iter().enumerate().find(|(_, l)| &l.name == name).ok_or_else(|| {
                        SetupError::NoLandmark {
                            file: self.name(),
                            key: key.clone(),
                            landmark: name.clone(),
                            world: w.name.clone(),
                        }
                    })?;
                let base = l.point();
                let v = s.servo_vertex_m;
                Ok(Some(ServoSetup {
                    landmark_index: index as u32,
                    point: [base[0] + v[0], base[1] + v[1], base[2] + v[2]],
                    offset: v,
                    params: ServoParams {
                        focal_px: w.camera.focal_for(w.camera.width_px),
                        misalignment_rad: sv.misalignment_deg.to_radians(),
                        aim_m: sv.aim_m,
                    },
                    width_px: w.camera.width_px,
                    height_px: w.camera.height_px,
                    camera_height_m: w.camera.height_m,
                    tracking: sv.offset,
                    calibrate: sv.calibrate_mount,
                    gate_rad: sv.gate_deg.to_radians(),
                    gate_range: sv.gate_range,
                }))
            })
            .collect()
    }

    /// What plan-level servoing needs: each vertex anchored on the nearest landmark (the vision
    /// request names a landmark and an offset from its point), and the camera.
    fn refine_setup(&self) -> Result<Option<RefineSetup>, SetupError> {
        let Some(r) = &self.mission.refine else { return Ok(None) };
        let w = self.world("[mission.refine]")?;
        // The vertices listed, then those the world model's selection gives (000 §5.2).
        let selected = r.select_contrast.map_or(Vec::new(), |c| {
            harvey_world::selection::corners(w, c).into_iter().map(|(p, _, _)| p).collect()
        });
        let vertices = r
            .vertices_m
            .iter()
            .chain(&selected)
            .map(|&v| {
                let dist = |p: [f64; 3]| (0..3).map(|k| (p[k] - v[k]).powi(2)).sum::<f64>();
                let (i, l) = w
                    .landmarks
                    .iter()
                    .enumerate()
                    .min_by(|a, b| dist(a.1.point()).total_cmp(&dist(b.1.point())))
                    .ok_or_else(|| SetupError::NoAnchor { file: self.name(), world: w.name.clone() })?;
                let p = l.point();
                Ok((i as u32, [v[0] - p[0], v[1] - p[1], v[2] - p[2]], v))
            })
            .collect::<Result<Vec<_>, SetupError>>()?;
        if vertices.len() < 2 {
            return Err(SetupError::FewVertices { file: self.name(), count: vertices.len() });
        }
        let c = &w.camera;
        Ok(Some(RefineSetup {
            vertices,
            camera: PinholeCamera {
                focal_px: c.focal_for(c.width_px),
                centre_px: [f64::from(c.width_px) / 2.0, f64::from(c.height_px) / 2.0],
                height_m: c.height_m,
            },
            params: RefineParams {
                prior_sd: [r.prior_sd[0], r.prior_sd[1], r.prior_sd[2].to_radians()],
                pitch_sd_rad: w.survey.calibration_sd_rad,
                image_sd_px: 0.5,
                map_sd_m: w.survey.position_sd_m,
                gate_px: r.gate_px,
            },
            template_px: r.template_px,
            min_score: r.min_score,
            max_sd_m: r.max_sd_m.unwrap_or(f64::INFINITY),
            growth: Growth::of(w),
            world: Some(w.clone()),
            choose: r.choose,
        }))
    }

    /// Plan-and-monitor for a `[mission.ptrans]` goal, in a world that has its locale.
    fn monitor(&self) -> Result<Option<Monitor>, SetupError> {
        let Some(goal) = &self.mission.ptrans else { return Ok(None) };
        let w = self.world("[mission.ptrans]")?;
        if !w.locales.iter().any(|l| l.name == goal.to) {
            return Err(SetupError::NoLocale {
                file: self.name(),
                locale: goal.to.clone(),
                world: w.name.clone(),
            });
        }
        Ok(Some(Monitor::new(goal.clone(), w.clone())))
    }
}

#[path = "setup_behaviour.rs"]
mod behaviour;

#[cfg(test)]
mod tests;
