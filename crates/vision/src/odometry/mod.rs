//! Visual odometry by stereo, stop to stop (003, the CMU rover after Moravec's Cart): at the
//! first stop the Moravec operator's features are ranged by stereo; at each next stop every
//! feature is reacquired in the new left image inside the box the predicted motion and its
//! margins allow, ranged again by stereo, features whose distances to the others changed are
//! pruned (rigidity), and the motion is solved by weighted least squares with the prediction as
//! a heavily weighted term, implausible residuals edited out one by one (Gennery). The features
//! that held, topped up with new ones, are carried to the next stop. Or, selectable, the
//! motion comes from Lucas registration of the old stop's patches in the new image
//! (`lucas.rs`), and the features are then reacquired where that motion puts them.

pub mod lucas;
pub mod magnify;
pub mod reacquire;
pub mod rig;
pub mod rigidity;
pub mod select;
pub mod solve;
mod track;

use crate::image::{Gray, GrayBuf, VisionError};
use crate::nc::{Correlator, Template};
use crate::pyramid::Pyramid;
use crate::stereo::{Stereo, StereoParams};
pub use lucas::LucasParams;
pub use rig::Rig;
pub use rigidity::Tolerance;
pub use solve::{Motion, Pair, Prior, Solution};

/// Everything the odometry needs to know; the numbers come from the mission's file.
#[derive(Debug, Clone, PartialEq)]
pub struct OdometryParams {
    pub rig: Rig,
    /// The stereo axis: band, near and far limits, patch, threshold, interest operator.
    pub stereo: StereoParams,
    /// The time axis: a reacquired patch must correlate at least this well.
    pub track_min_score: f32,
    /// The reacquisition box spans the prediction this many standard deviations either way.
    pub box_sigmas: f64,
    pub rigidity: Tolerance,
    /// Gennery's editing drops a feature whose normalised squared residual exceeds this.
    pub edit_chi2: f64,
    /// No motion is solved on fewer features.
    pub min_features: usize,
    /// 003's reasonableness limit: a solved motion further from the prediction than this
    /// (its squared distance in the prediction's standard deviations, a chi-square with three
    /// degrees of freedom) is a blunder, not a motion: no solution is reported.
    pub plausible_chi2: f64,
    /// A new feature is taken only this far (pixels) from every carried one.
    pub spacing_px: f32,
    /// A new feature is taken only where its patch's gradients turn: the structure tensor's
    /// eigenvalues at least this far from an edge's (`select::turn_ratio`; 0 takes every one).
    pub min_turn: f64,
    pub solver: Solver,
}

/// How the motion between stops is found (003 compares the two).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solver {
    /// Features matched one by one, then the motion solved on their 3-D points.
    MatchThenSolve,
    /// All patches registered at once on the images (Lucas).
    Lucas(LucasParams),
}

/// What a stop's solution rests on.
#[derive(Debug, Clone, PartialEq)]
pub struct StepReport {
    pub solution: Solution,
    /// Features carried from the last stop, and how many were found again and ranged.
    pub carried: usize,
    pub reacquired: usize,
    /// Dropped by the rigidity test.
    pub pruned: usize,
    /// The factor the stereo model's errors were scaled by, from the pairs' spread.
    pub error_scale: f64,
    /// Features carried to the next stop (those that held and new ones).
    pub features: usize,
}

/// Why a stop gave no motion. The odometry starts afresh from the stop's images either way, so
/// the next stop is solved against this one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OdometryError {
    #[error(transparent)]
    Vision(#[from] VisionError),
    #[error(
        "no motion solution: {reacquired} of {carried} features found again, {left} after pruning and editing, {needed} needed"
    )]
    NoSolution { carried: usize, reacquired: usize, left: usize, needed: usize },
    #[error(
        "the motion solved is {chi2:.1} (chi-square) from the prediction, past the reasonableness limit {limit}"
    )]
    Implausible { report: Box<StepReport>, chi2: f64, limit: f64 },
    #[error("the stereo pair is {got:?}, the odometry started on {started:?}")]
    SizeChanged { got: [usize; 2], started: [usize; 2] },
}

/// A feature carried from one stop to the next.
#[derive(Debug, Clone)]
struct Feature {
    /// In the robot frame of the stop it was last seen at.
    point: [f64; 3],
    /// Where it was in that stop's left image, and the patch round it.
    at: [f32; 2],
    patch: GrayBuf,
}

/// The odometry with its features and buffers.
#[derive(Debug)]
pub struct VisualOdometry {
    params: OdometryParams,
    stereo: Stereo,
    correlator: Correlator,
    /// The reacquisition's template, its buffers reused from feature to feature.
    template: Option<Template>,
    features: Vec<Feature>,
    /// How many of `features` (the first) held at the last stop: found again, rigid and
    /// agreeing with the motion (none after a start).
    held: usize,
    size: Option<[usize; 2]>,
    pairs: Vec<Pair>,
    found: Vec<Feature>,
    scratch: Vec<bool>,
    /// Lucas registration's pyramids of the last stop's left image and this one's.
    pyramids: [Pyramid; 2],
}

impl VisualOdometry {
    pub fn new(params: OdometryParams) -> Self {
        Self {
            params,
            stereo: Stereo::default(),
            correlator: Correlator::default(),
            template: None,
            features: Vec::new(),
            held: 0,
            size: None,
            pairs: Vec::new(),
            found: Vec::new(),
            scratch: Vec::new(),
            pyramids: [Pyramid::default(), Pyramid::default()],
        }
    }

    /// The settings it runs with.
    pub fn params(&self) -> &OdometryParams {
        &self.params
    }

    /// The features carried now: their left-image positions and robot-frame points.
    pub fn features(&self) -> impl Iterator<Item = ([f32; 2], [f64; 3])> + '_ {
        self.features.iter().map(|f| (f.at, f.point))
    }

    /// The features that held at the last stop (found again, rigid with the others and agreeing
    /// with the motion): points seen from two stops, not a single match that may be a blunder.
    pub fn held(&self) -> impl Iterator<Item = ([f32; 2], [f64; 3])> + '_ {
        self.features().take(self.held)
    }

    /// The first stop (or a fresh start): ranges the pair's features; returns how many.
    pub fn start(&mut self, left: &Gray<'_>, right: &Gray<'_>) -> Result<usize, OdometryError> {
        self.features.clear();
        self.held = 0;
        self.size = Some([left.width, left.height]);
        if let Solver::Lucas(lp) = self.params.solver {
            self.pyramids[0].build(left, lp.levels)?;
        }
        self.top_up(left, right)?;
        Ok(self.features.len())
    }

    /// The next stop, after a motion predicted as `prior`: the motion solved, or why not.
    pub fn step(
        &mut self,
        left: &Gray<'_>,
        right: &Gray<'_>,
        prior: &Prior,
    ) -> Result<StepReport, OdometryError> {
        let got = [left.width, left.height];
        match self.size {
            Some(started) if started != got => return Err(OdometryError::SizeChanged { got, started }),
            None => {
                self.start(left, right)?;
                return Err(self.no_solution(0, 0, 0));
            }
            Some(_) => {}
        }
        let carried = self.features.len();
        let registered = match self.params.solver {
            Solver::MatchThenSolve => None,
            Solver::Lucas(lp) => match self.register(left, prior, &lp) {
                Ok(r) => Some(r),
                Err(e) => {
                    self.start(left, right)?;
                    return Err(e);
                }
            },
        };
        // After a registration the features are looked for where its motion puts them, in a
        // box of its own uncertainty but never under 1 cm and 0.3 degree a side per sd (a
        // registration's covariance takes no account of the depths' own errors).
        let near = registered.as_ref().map(|r| Prior {
            motion: r.motion,
            sd: std::array::from_fn(|k| r.covariance[k][k].sqrt().max([0.01, 0.01, 0.005][k])),
        });
        self.reacquire(left, right, near.as_ref().unwrap_or(prior))?;
        let reacquired = self.pairs.len();
        let mut active = vec![true; reacquired];
        let p = &self.params;
        let pruned = rigidity::prune(&p.rig, &self.pairs, &mut active, p.rigidity, &mut self.scratch);
        let variance = pruned.scale * pruned.scale;
        for pair in &mut self.pairs {
            pair.old_cov = pair.old_cov.map(|c| c * variance);
            pair.new_cov = pair.new_cov.map(|c| c * variance);
        }
        let solved = match registered {
            None => solve::solve(&self.pairs, &mut active, prior, p.edit_chi2, p.min_features),
            Some(r) => lucas_solution(r, &self.pairs, &active, p.min_features),
        };
        // The features that held go on; the odometry restarts from this stop if none did.
        let mut held = std::mem::take(&mut self.found);
        self.features.clear();
        self.features.extend(held.drain(..).zip(&active).filter(|(_, a)| **a).map(|(f, _)| f));
        self.found = held;
        self.held = self.features.len();
        let solution = match solved {
            Ok(s) => s,
            Err(e) => {
                self.start(left, right)?;
                return Err(self.no_solution(carried, reacquired, e.left));
            }
        };
        let chi2 = solve::departure(&solution.motion, prior);
        if chi2.is_nan() || chi2 > p.plausible_chi2 {
            let report = StepReport {
                solution,
                carried,
                reacquired,
                pruned: pruned.dropped,
                error_scale: pruned.scale,
                features: 0,
            };
            let limit = p.plausible_chi2;
            self.start(left, right)?;
            return Err(OdometryError::Implausible { report: Box::new(report), chi2, limit });
        }
        self.top_up(left, right)?;
        Ok(StepReport {
            solution,
            carried,
            reacquired,
            pruned: pruned.dropped,
            error_scale: pruned.scale,
            features: self.features.len(),
        })
    }

    /// Lucas registration of the last stop's features in this stop's left image.
    fn register(
        &mut self,
        left: &Gray<'_>,
        prior: &Prior,
        lp: &LucasParams,
    ) -> Result<lucas::Registration, OdometryError> {
        self.pyramids.swap(0, 1);
        self.pyramids[0].build(left, lp.levels)?;
        let anchors: Vec<lucas::Anchor> =
            self.features.iter().map(|f| lucas::Anchor { at: f.at, point: f.point }).collect();
        let [new, old] = &self.pyramids;
        // The differences are weighed by the frame's own noise (a grey level at least).
        let sd = f64::from(crate::noise::noise_sigma(left, left.full())).max(1.0);
        lucas::register(&self.params.rig, &old.levels, &new.levels, &anchors, prior, lp, sd)
            .filter(|r| r.patches >= self.params.min_features)
            .ok_or_else(|| self.no_solution(anchors.len(), 0, 0))
    }

    fn no_solution(&self, carried: usize, reacquired: usize, left: usize) -> OdometryError {
        OdometryError::NoSolution { carried, reacquired, left, needed: self.params.min_features }
    }
}

/// A registration as a solution: the stereo pairs that held, and how well they agree with it.
fn lucas_solution(
    r: lucas::Registration,
    pairs: &[Pair],
    active: &[bool],
    needed: usize,
) -> Result<Solution, solve::TooFew> {
    let held: Vec<&Pair> = pairs.iter().zip(active).filter(|(_, a)| **a).map(|(p, _)| p).collect();
    if held.is_empty() {
        return Err(solve::TooFew { left: 0, needed });
    }
    let sum: f64 = held.iter().map(|p| solve::residual(p, &r.motion).1).sum();
    Ok(Solution {
        motion: r.motion,
        covariance: r.covariance,
        edited: 0,
        used: r.patches,
        rms: (sum / held.len() as f64).sqrt(),
    })
}
