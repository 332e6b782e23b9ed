//! The set-up of the behaviours a mission may run as its mode (docking, the pole hunt, CMU's
//! navigation, door finding, path following, obstacle avoidance by depth from motion): each
//! from its goal table and the world, with the acceptor files next to the launch file.

use std::path::Path;

use crate::behaviours::Behaviour;
use crate::behaviours::depth_obstacles::DepthObstacles;
use crate::behaviours::docking::Docking;
use crate::behaviours::door_finding::DoorFinding;
use crate::behaviours::fsa::Fsa;
use crate::behaviours::neptune::{Neptune, Sonar};
use crate::behaviours::path_follow;
use crate::behaviours::pole_hunt::PoleHunt;

use super::{SetupError, Site};

impl Site<'_> {
    /// The acceptor of goal table `table` (its `fsa`, a file next to the launch file), which
    /// must have the state `done` its `field` names.
    pub(super) fn acceptor(
        &self,
        table: &str,
        file: &str,
        field: &str,
        done: &str,
    ) -> Result<Fsa, SetupError> {
        let path = self.file.parent().unwrap_or(Path::new(".")).join(file);
        let key = format!("{table}.fsa");
        let text = std::fs::read_to_string(&path).map_err(|source| SetupError::ReadAcceptor {
            file: self.name(),
            key: key.clone(),
            path: path.clone(),
            source,
        })?;
        let fsa = Fsa::parse(&text, &path.display().to_string()).map_err(|source| SetupError::Acceptor {
            file: self.name(),
            key: key.clone(),
            source,
        })?;
        if !fsa.states.iter().any(|s| s.name == done) {
            return Err(SetupError::NoState {
                file: self.name(),
                key: format!("{table}.{field}"),
                acceptor: path.display().to_string(),
                state: done.to_owned(),
            });
        }
        Ok(fsa)
    }

    /// The docking behaviour or the pole hunt (the acceptor, the camera, the sonar, the seed),
    /// CMU's navigation (its start, the sonar ring), door finding (the sonar ring's radius, the
    /// start), path following (the path's edges, the camera), or depth from motion (the camera).
    pub(super) fn behaviour(&self, seed: u64) -> Result<Option<Behaviour>, SetupError> {
        let m = self.mission;
        if let Some(g) = &m.neptune {
            let w = self.world("[mission.neptune]")?;
            let r = &w.robot;
            let sonar =
                Sonar { ring_m: r.sonar_ring_radius_m, beam_rad: r.sonar_beam_width_deg.to_radians() };
            let n = Neptune::new(*g, w.start, sonar);
            return Ok(Some(Behaviour::Neptune(Box::new(n))));
        }
        if let Some(g) = &m.path {
            let w = self.world("[mission.path]")?;
            let p = path_follow::in_world(g, w).map_err(|landmark| SetupError::NoLandmark {
                file: self.name(),
                key: "mission.path.segments".to_owned(),
                landmark,
                world: w.name.clone(),
            })?;
            return Ok(Some(Behaviour::Path(Box::new(p))));
        }
        if let Some(g) = &m.depth {
            let w = self.world("[mission.depth]")?;
            let c = &w.camera;
            let camera = [c.focal_for(c.width_px), f64::from(c.width_px), f64::from(c.height_px), c.height_m];
            let d = DepthObstacles::new(g.clone(), camera, w.robot.sonar_ring_radius_m, w.start);
            return Ok(Some(Behaviour::Depth(Box::new(d))));
        }
        if let Some(g) = &m.door {
            let w = self.world("[mission.door]")?;
            let d = DoorFinding::new(g.clone(), w.robot.sonar_ring_radius_m, w.start);
            return Ok(Some(Behaviour::Door(Box::new(d))));
        }
        let key = match (&m.docking, &m.poles) {
            (Some(_), _) => "[mission.docking]",
            (None, Some(_)) => "[mission.poles]",
            (None, None) => return Ok(None),
        };
        let w = self.world(key)?;
        let c = &w.camera;
        let (focal, width, height) = (c.focal_for(c.width_px), f64::from(c.width_px), f64::from(c.height_px));
        let ring = w.robot.sonar_ring_radius_m;
        if let Some(g) = &m.docking {
            let fsa = self.acceptor("mission.docking", &g.fsa, "docked_state", &g.docked_state)?;
            let d = Docking::new(g.clone(), fsa, (focal, width, height), ring, seed);
            return Ok(Some(Behaviour::Docking(Box::new(d))));
        }
        let Some(g) = &m.poles else { return Ok(None) };
        let fsa = self.acceptor("mission.poles", &g.fsa, "parked_state", &g.parked_state)?;
        let poles = w
            .poles
            .as_ref()
            .ok_or_else(|| SetupError::NoPoles { file: self.name(), world: w.name.clone() })?;
        let hunt = PoleHunt::new(g.clone(), fsa, (focal, width), ring, poles.side_m, seed, w.start);
        Ok(Some(Behaviour::Poles(Box::new(hunt))))
    }
}
