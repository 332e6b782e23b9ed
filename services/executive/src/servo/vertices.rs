//! What plan-level servoing (000 §5.6) needs from the world, and which of its landmark vertices
//! are worth asking for from a pose: in the image, at a usable range, not hidden behind a wall.

use harvey_msgs::Pose2;

use crate::servo::choose::most_telling;
use crate::servo::pose::{PinholeCamera, RefineParams};

/// What refining needs from the world: each vertex with the landmark its request is anchored
/// on (the nearest) and its offset from that landmark's point, and the camera.
#[derive(Debug, Clone, PartialEq)]
pub struct RefineSetup {
    /// `(landmark index, offset from its point, the vertex in the world)`.
    pub vertices: Vec<(u32, [f64; 3], [f64; 3])>,
    pub camera: PinholeCamera,
    pub params: RefineParams,
    pub template_px: u32,
    pub min_score: f64,
    /// Fixes placing the robot no better than this are refused (`mission.refine.max_sd_m`).
    pub max_sd_m: f64,
    /// How fast dead reckoning loses the pose: the prior's growth per metre travelled.
    pub growth: Growth,
    /// The world, to ask only for vertices in view and not hidden behind a wall; without it,
    /// every vertex is asked for.
    pub world: Option<harvey_world::World>,
    /// Which `MAX_ASKED` to ask for when more are in view.
    pub choose: Choose,
}

/// How a fix chooses among more vertices in view than it can ask for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Choose {
    /// The nearest.
    #[default]
    Nearest,
    /// Those that most shrink the fix's expected position spread (`choose.rs`).
    MostTelling,
}

/// How much less the believed pose is worth per metre travelled and per radian turned since the
/// last fix, from the world's terrain statistics (002 §3.2 Table 3; the worst terrain of the
/// world): the heading drifts by `drift + sd` degrees a foot (its sign unknown to the robot, as
/// the UMS takes it) and a turn falls short by `loss + sd` of itself, the distance falls short
/// by `loss + sd` of itself, and the heading's drift moves the robot sideways by half of itself
/// times the distance.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Growth {
    pub heading_rad_per_m: f64,
    pub heading_per_turn: f64,
    pub along_per_m: f64,
}

impl Growth {
    /// The worst of `world`'s terrains.
    pub fn of(world: &harvey_world::World) -> Self {
        let ft_per_m = 1.0 / harvey_geometry::FT;
        world.terrain.values().fold(Self::default(), |g, t| Self {
            heading_rad_per_m: g
                .heading_rad_per_m
                .max(((t.drift_deg_per_ft + t.drift_sd_deg_per_ft) * ft_per_m).to_radians()),
            heading_per_turn: g
                .heading_per_turn
                .max(t.rotational_loss_deg_per_deg + t.rotational_sd_deg_per_deg),
            along_per_m: g.along_per_m.max(t.translational_loss_ft_per_ft + t.translational_sd_ft_per_ft),
        })
    }

    /// `params` with its prior widened for `travelled_m` of dead reckoning and `turned_rad` of
    /// turns.
    pub fn widen(&self, params: &RefineParams, travelled_m: f64, turned_rad: f64) -> RefineParams {
        let drift = self.heading_rad_per_m * travelled_m;
        let heading = drift + self.heading_per_turn * turned_rad;
        let position = (self.along_per_m * travelled_m).max(drift * travelled_m / 2.0);
        let [x, y, h] = params.prior_sd;
        RefineParams { prior_sd: [x.hypot(position), y.hypot(position), h.hypot(heading)], ..*params }
    }
}

/// At most this many vertices are asked for at once (the vision request queue holds 16).
pub const MAX_ASKED: usize = 16;
/// Fewer vertices in view than this, and no fix is tried.
pub const MIN_ASKED: usize = 3;

impl RefineSetup {
    /// The prior of a fix taken with `belief` as it stands: the configured one, widened by the
    /// travel and turns since the last fix.
    pub fn prior(&self, belief: &crate::servo::belief::Belief) -> RefineParams {
        self.growth.widen(&self.params, belief.travelled_m(), belief.turned_rad())
    }

    /// The vertices (indices) worth asking for from `pose`: in the image clear of its edges by a
    /// template, 0.5 to 20 m ahead, with no wall between; of those, `MAX_ASKED` by `choose`
    /// (the most telling for a fix with `params`' priors), in list order.
    pub fn in_view(&self, pose: Pose2, image_px: [f64; 2], params: &RefineParams) -> Vec<usize> {
        let margin = f64::from(self.template_px);
        let mut seen: Vec<(usize, f64)> = self
            .vertices
            .iter()
            .enumerate()
            .filter_map(|(i, &(_, _, v))| {
                let [u, w] = self.camera.project(pose, v)?;
                let inside = (margin..image_px[0] - margin).contains(&u)
                    && (margin..image_px[1] - margin).contains(&w);
                let (dx, dy) = (v[0] - pose.x_m, v[1] - pose.y_m);
                let d = dx.hypot(dy);
                let clear = self.world.as_ref().is_none_or(|world| {
                    world
                        .cast_ray([pose.x_m, pose.y_m], [dx / d, dy / d], d)
                        .is_none_or(|h| h.distance_m > d - 0.05)
                });
                (inside && clear && (0.5..20.0).contains(&d)).then_some((i, d))
            })
            .collect();
        let mut ids: Vec<usize> = match self.choose {
            Choose::Nearest => {
                seen.sort_by(|a, b| a.1.total_cmp(&b.1));
                seen.into_iter().take(MAX_ASKED).map(|(i, _)| i).collect()
            }
            Choose::MostTelling => {
                let candidates: Vec<(usize, [f64; 3])> =
                    seen.iter().map(|&(i, _)| (i, self.vertices[i].2)).collect();
                most_telling(&self.camera, pose, params, &candidates, MAX_ASKED)
            }
        };
        ids.sort_unstable();
        ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prior_widens_with_the_path_by_the_terrain_s_drift() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../worlds/hallway.toml");
        let world = harvey_world::World::load(std::path::Path::new(path)).expect("world");
        let g = Growth::of(&world);
        let p = crate::servo::pose::tests::params();
        assert_eq!(g.widen(&p, 0.0, 0.0), p, "no travel, no change");
        // A 7 m leg on concrete (the worst): (0.30 + 0.14) deg/ft for 23 ft is 10 deg of heading,
        // and 0.6 m sideways from half of it.
        let w = g.widen(&p, 7.0, 0.0);
        assert!((w.prior_sd[2].to_degrees() - p.prior_sd[2].to_degrees().hypot(10.1)).abs() < 0.1, "{w:?}");
        assert!(w.prior_sd[0] > 0.6 && w.prior_sd[1] == w.prior_sd[0], "{w:?}");
    }

    #[test]
    fn a_turn_since_the_last_fix_widens_the_heading_s_prior_and_a_fix_starts_it_afresh() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../worlds/hallway.toml");
        let world = harvey_world::World::load(std::path::Path::new(path)).expect("world");
        let params = crate::servo::pose::tests::params();
        let setup = RefineSetup {
            vertices: Vec::new(),
            camera: crate::servo::pose::tests::cam(),
            params,
            template_px: 16,
            min_score: 0.9,
            max_sd_m: f64::INFINITY,
            growth: Growth::of(&world),
            world: None,
            choose: Choose::Nearest,
        };
        let mut belief = crate::servo::belief::Belief::default();
        assert_eq!(setup.prior(&belief), params, "nothing done yet: the configured prior");
        // A quarter turn on the spot: Table 3's rotational loss and spread of the turn (tile's
        // 0.018 + 0.006, the worst) join the heading's spread; no travel, no position lost.
        let quarter = std::f64::consts::FRAC_PI_2;
        belief.set_odometry(Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: quarter });
        let turned = setup.prior(&belief).prior_sd;
        assert!((turned[2] - params.prior_sd[2].hypot(0.024 * quarter)).abs() < 1e-9, "{turned:?}");
        assert_eq!(turned[..2], params.prior_sd[..2]);
        // Back the other way: a turn counts either way.
        belief.set_odometry(Pose2::default());
        let back = setup.prior(&belief).prior_sd;
        assert!((back[2] - params.prior_sd[2].hypot(0.048 * quarter)).abs() < 1e-9, "{back:?}");
        // A fix starts the count afresh.
        belief.fix(Pose2::default());
        assert_eq!(setup.prior(&belief), params);
    }
}
