//! Obstacle extraction from tracked depths (001 §2.3): which points stand off the floor, by the
//! paper's fit of image row against inverse depth ([`obstacles`]), or against the floor a
//! calibrated camera expects ([`standing_off_floor`]).

use crate::depth::Track;

/// Obstacle extraction: fits image row against `1/depth` over the tracked points below the
/// FOE (robustly: refits without the worst point while any lies off by more than the
/// tolerance), and returns, for each track, whether it stands off the ground line (`None`:
/// its depth is not yet known to better than `max_rel_sd`). The tolerance is `tol_px` plus
/// `tol_frac` of the point's height below the FOE in the image, as depth errors are relative.
pub fn obstacles(
    tracks: &[&Track],
    foe_v: f32,
    tol_px: f32,
    tol_frac: f32,
    max_rel_sd: f32,
) -> Vec<Option<bool>> {
    let tol = |v: f64| f64::from(tol_px) + f64::from(tol_frac) * (v - f64::from(foe_v)).max(0.0);
    let pts: Vec<(usize, f64, f64)> = tracks
        .iter()
        .enumerate()
        .filter_map(|(i, t)| {
            let known = t.depth.filter(|(z, sd)| *z > 0.0 && *sd <= max_rel_sd * *z);
            known.map(|(z, _)| (i, 1.0 / f64::from(z), f64::from(t.at[1])))
        })
        .collect();
    let mut ground: Vec<(usize, f64, f64)> = pts.iter().copied().filter(|p| p.2 > f64::from(foe_v)).collect();
    let mut line = (0.0, 0.0);
    while ground.len() >= 3 {
        let n = ground.len() as f64;
        let (sx, sy) = ground.iter().fold((0.0, 0.0), |a, p| (a.0 + p.1, a.1 + p.2));
        let (sxx, sxy) = ground.iter().fold((0.0, 0.0), |a, p| (a.0 + p.1 * p.1, a.1 + p.1 * p.2));
        let slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
        line = ((sy - slope * sx) / n, slope);
        let worst = ground
            .iter()
            .enumerate()
            .map(|(k, p)| (k, (p.2 - line.0 - line.1 * p.1).abs() / tol(line.0 + line.1 * p.1)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((k, e)) if e > 1.0 => {
                ground.swap_remove(k);
            }
            _ => break,
        }
    }
    let mut out = vec![None; tracks.len()];
    for (i, x, v) in pts {
        let ground_v = line.0 + line.1 * x;
        out[i] = Some(v < ground_v - tol(ground_v));
    }
    out
}

/// Obstacle extraction with a calibrated camera (its height above the floor `camera_height_m`
/// and the horizon's row `foe_v`, focal length `focal_px`): a point's height above the floor
/// is `h - (v - v0) Z / f`; it stands off the floor when that height, less twice its spread
/// (from the depth's), is above `min_height_m`. `None` where the depth is not yet known to
/// within `max_rel_sd` of itself. Where the points are mostly an obstacle's (a cone filling the
/// window), the paper's fit takes the obstacle for the floor; the calibration does not.
pub fn standing_off_floor(
    tracks: &[&Track],
    foe_v: f32,
    focal_px: f32,
    camera_height_m: f32,
    min_height_m: f32,
    max_rel_sd: f32,
) -> Vec<Option<bool>> {
    tracks
        .iter()
        .map(|t| {
            let (z, sd) = t.depth.filter(|(z, sd)| *z > 0.0 && *sd <= max_rel_sd * *z)?;
            let below = (t.at[1] - foe_v) / focal_px;
            let height = camera_height_m - below * z;
            Some(height - 2.0 * below.abs() * sd > min_height_m)
        })
        .collect()
}
