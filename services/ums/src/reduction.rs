//! Uncertainty reduction by landmark sightings (002 §3.4): a class I sighting (a vertical line at
//! a bearing) confines the robot to a cone from the landmark; class II (a point of known height:
//! bearing and range) to an annular sector; class III (a ground line: relative heading and
//! lateral offset) to a strip and a heading interval. Each slices the polygon and the wedge,
//! keeping them convex; a sighting that leaves nothing is rejected and the map kept.

use std::f64::consts::TAU;

use crate::geometry::{self, Pt};
use crate::map::{Map, wrap};

/// What a vision worker measured of a landmark, in the robot frame, with its standard errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Observation {
    /// Class I: the landmark's bearing from the robot's heading (counter-clockwise positive).
    Bearing { bearing_rad: f64, sd_rad: f64 },
    /// Class II: bearing and horizontal range.
    BearingRange { bearing_rad: f64, sd_rad: f64, range_m: f64, range_sd_m: f64 },
    /// Class III: the robot's heading minus the line's direction, and the robot's signed
    /// distance from the line (left of its direction positive).
    GroundLine { heading_rad: f64, heading_sd_rad: f64, offset_m: f64, offset_sd_m: f64 },
}

/// Where the landmark is (world frame), as the world model says, and how sure that is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Known {
    pub at: Pt,
    /// Class III: the line's other end.
    pub to: Option<Pt>,
    pub position_sd_m: f64,
}

/// Why a sighting was not applied.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Rejection {
    #[error("the sighting holds a non-finite number")]
    NotFinite,
    #[error("a class III sighting needs a landmark line with two ends")]
    NoLine,
    #[error("no position in the map is consistent with the sighting")]
    NoPosition,
    #[error("no heading in the wedge is consistent with the sighting")]
    NoHeading,
    /// `consensus.rs`: the frame's other sightings imply another heading.
    #[error("the other landmarks seen in the same frame disagree with it: a false match")]
    Disagrees,
    /// `consensus.rs`: the bearing is further from the map's prediction than its spread allows.
    #[error("its bearing is further from the map's prediction than the map's spread allows: a false match")]
    Implausible,
}

/// Keeps the side of the line through `o` along `d` to its left, widened by `margin`.
fn keep_left(poly: &[Pt], o: Pt, d: Pt, margin: f64) -> Vec<Pt> {
    let len = d[0].hypot(d[1]);
    let n = [d[1] / len, -d[0] / len];
    geometry::clip(poly, n, n[0] * o[0] + n[1] * o[1] + margin)
}

fn dir(a: f64) -> Pt {
    [a.cos(), a.sin()]
}

/// Intersects the wedge with `[lo, hi]`, taken a whole turn either way where that overlaps the
/// wedge more (a wide wedge reaches past half a turn from its centre).
fn cut_wedge(map: &mut Map, lo: f64, hi: f64) -> Result<(), Rejection> {
    let [wlo, whi] = map.wedge();
    let shift = wrap(lo - map.heading_rad) - (lo - map.heading_rad);
    let overlap = |k: f64| (wlo.max(lo + shift + k), whi.min(hi + shift + k));
    let (nlo, nhi) = [-TAU, TAU]
        .into_iter()
        .map(overlap)
        .fold(overlap(0.0), |best, o| if o.1 - o.0 > best.1 - best.0 { o } else { best });
    if nlo > nhi {
        return Err(Rejection::NoHeading);
    }
    map.heading_rad = map.heading_rad.clamp(nlo, nhi);
    map.cw_rad = map.heading_rad - nlo;
    map.ccw_rad = nhi - map.heading_rad;
    Ok(())
}

/// Slices the map by one sighting of a landmark at `known`, at `sigmas` deviations.
pub fn apply(map: &Map, known: &Known, obs: &Observation, sigmas: f64) -> Result<Map, Rejection> {
    let finite = match *obs {
        Observation::Bearing { bearing_rad, sd_rad } => bearing_rad.is_finite() && sd_rad.is_finite(),
        Observation::BearingRange { bearing_rad, sd_rad, range_m, range_sd_m } => {
            [bearing_rad, sd_rad, range_m, range_sd_m].iter().all(|v| v.is_finite())
        }
        Observation::GroundLine { heading_rad, heading_sd_rad, offset_m, offset_sd_m } => {
            [heading_rad, heading_sd_rad, offset_m, offset_sd_m].iter().all(|v| v.is_finite())
        }
    };
    if !finite || !known.at.iter().all(|v| v.is_finite()) {
        return Err(Rejection::NotFinite);
    }
    let mut out = map.clone();
    let l = known.at;
    let margin = sigmas * known.position_sd_m;
    match *obs {
        Observation::Bearing { bearing_rad, sd_rad }
        | Observation::BearingRange { bearing_rad, sd_rad, .. } => {
            let e = sigmas * sd_rad;
            let [lo, hi] = map.wedge();
            // Directions from the robot to the landmark, and the cone of robot positions.
            let (psi0, psi1) = (lo + bearing_rad - e, hi + bearing_rad + e);
            if psi1 - psi0 < std::f64::consts::PI {
                let (a0, a1) = (psi0 + std::f64::consts::PI, psi1 + std::f64::consts::PI);
                out.polygon = keep_left(&out.polygon, l, dir(a0), margin);
                out.polygon = keep_left(&out.polygon, l, [-dir(a1)[0], -dir(a1)[1]], margin);
                if let Observation::BearingRange { range_m, range_sd_m, .. } = *obs {
                    let r_out = range_m + sigmas * range_sd_m + margin;
                    let r_in = (range_m - sigmas * range_sd_m - margin).max(0.0);
                    // Outer arc: tangent half-planes every 10 degrees across the cone.
                    let steps = (((a1 - a0) / 10f64.to_radians()).ceil() as usize).max(1);
                    for k in 0..=steps {
                        let a = a0 + (a1 - a0) * k as f64 / steps as f64;
                        let n = dir(a);
                        out.polygon = geometry::clip(&out.polygon, n, n[0] * l[0] + n[1] * l[1] + r_out);
                    }
                    // Inner arc: beyond its chord.
                    if r_in > 0.0 {
                        let p0 = [l[0] + r_in * a0.cos(), l[1] + r_in * a0.sin()];
                        let p1 = [l[0] + r_in * a1.cos(), l[1] + r_in * a1.sin()];
                        out.polygon = keep_left(&out.polygon, p1, [p0[0] - p1[0], p0[1] - p1[1]], 0.0);
                    }
                }
            }
            if out.polygon.is_empty() {
                return Err(Rejection::NoPosition);
            }
            // The headings each remaining position allows (bearing extremes lie at vertices).
            if !geometry::contains(&out.polygon, l, margin) {
                let psis: Vec<f64> = out
                    .polygon
                    .iter()
                    .map(|p| {
                        map.heading_rad
                            + wrap((l[1] - p[1]).atan2(l[0] - p[0]) - bearing_rad - map.heading_rad)
                    })
                    .collect();
                let nearest = geometry::nearest_point(&out.polygon, l);
                let dist = (nearest[0] - l[0]).hypot(nearest[1] - l[1]).max(1e-3);
                let widen = e + (margin / dist).atan();
                let lo = psis.iter().copied().fold(f64::INFINITY, f64::min) - widen;
                let hi = psis.iter().copied().fold(f64::NEG_INFINITY, f64::max) + widen;
                cut_wedge(&mut out, lo, hi)?;
            }
        }
        Observation::GroundLine { heading_rad, heading_sd_rad, offset_m, offset_sd_m } => {
            let to = known.to.ok_or(Rejection::NoLine)?;
            let d = [to[0] - l[0], to[1] - l[1]];
            let len = d[0].hypot(d[1]);
            if len < 1e-9 {
                return Err(Rejection::NoLine);
            }
            let u = [d[0] / len, d[1] / len];
            let left = [-u[1], u[0]];
            let e = sigmas * offset_sd_m + margin;
            let (near, far) = (offset_m - e, offset_m + e);
            // Keep offset <= far and offset >= near.
            let at = |o: f64| [l[0] + left[0] * o, l[1] + left[1] * o];
            out.polygon = keep_left(&out.polygon, at(far), [-u[0], -u[1]], 0.0);
            out.polygon = keep_left(&out.polygon, at(near), u, 0.0);
            if out.polygon.is_empty() {
                return Err(Rejection::NoPosition);
            }
            let gamma = d[1].atan2(d[0]);
            let eh = sigmas * heading_sd_rad;
            cut_wedge(&mut out, gamma + heading_rad - eh, gamma + heading_rad + eh)?;
        }
    }
    if !geometry::contains(&out.polygon, out.centre, 1e-9) {
        out.centre = geometry::nearest_point(&out.polygon, out.centre);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_heading_past_half_a_turn_inside_a_wide_wedge_cuts_it_and_is_not_refused() {
        let mut map = Map::exact(0.0, 0.0, 0.0);
        (map.cw_rad, map.ccw_rad) = (1.0, 5.0);
        // -2.2..-1.8 rad is 4.08..4.48 rad counter-clockwise: inside the wedge.
        cut_wedge(&mut map, -2.2, -1.8).expect("inside the wedge");
        let [lo, hi] = map.wedge();
        assert!((lo - (TAU - 2.2)).abs() < 1e-9 && (hi - (TAU - 1.8)).abs() < 1e-9, "{lo} {hi}");
        // A narrow wedge still refuses what lies outside it.
        let mut narrow = Map::exact(0.0, 0.0, 0.0);
        (narrow.cw_rad, narrow.ccw_rad) = (0.1, 0.1);
        assert!(matches!(cut_wedge(&mut narrow, 0.5, 0.7), Err(Rejection::NoHeading)));
        cut_wedge(&mut narrow, 0.05, 0.7).expect("overlaps");
        let [lo, hi] = narrow.wedge();
        assert!((lo - 0.05).abs() < 1e-9 && (hi - 0.1).abs() < 1e-9, "{lo} {hi}");
    }
}
