//! Which start-up points depth from motion can measure (001 §2.3): those whose patch does not
//! repeat along their radial line from the focus of expansion, where the next frame's match is
//! searched.

use crate::depth::{DepthParams, radial};
use crate::image::{Gray, VisionError};

/// A start-up point is dropped when its patch moved this far or further along its radial line
/// (px, up to the start-up search's reach) still correlates this well with itself; the
/// interest operator offers this many times the points wanted, strongest first.
pub(crate) const RADIAL_SHIFT_PX: f32 = 5.0;
pub(crate) const RADIAL_SAMENESS: f64 = 0.85;
pub(crate) const RADIAL_CANDIDATES: usize = 3;

/// Whether the patch at `at` differs from itself moved out along its radial line by anything
/// from [`RADIAL_SHIFT_PX`] to the start-up search's reach (normalised correlation below
/// [`RADIAL_SAMENESS`] at every whole pixel). A point on an edge that runs out from the FOE (a
/// path's edge, a wall's foot, seen ahead) slides along it, and one on a repeated pattern along
/// its line (paving slabs) has a look-alike there: the start-up match, which searches that
/// line, could take either for it.
pub(crate) fn radially_distinct(img: &Gray<'_>, p: &DepthParams, at: [f32; 2]) -> Result<bool, VisionError> {
    let half = (p.patch / 2) as isize;
    let (d, _) = radial(p, at);
    let centre = [(at[0] - 0.5).round() as isize, (at[1] - 0.5).round() as isize];
    let inside = |c: [isize; 2]| {
        c[0] >= half && c[1] >= half && c[0] + half < img.width as isize && c[1] + half < img.height as isize
    };
    if !inside(centre) {
        return Ok(false);
    }
    let reach = p.startup_reach_px.max(RADIAL_SHIFT_PX).ceil() as usize;
    for step in (RADIAL_SHIFT_PX as usize)..=reach {
        let moved = [
            centre[0] + (d[0] * step as f32).round() as isize,
            centre[1] + (d[1] * step as f32).round() as isize,
        ];
        if !inside(moved) {
            break;
        }
        if patch_correlation(img, centre, moved, half) >= RADIAL_SAMENESS {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Normalised correlation of the square patches of half-side `half` round `a` and `b` (0 where
/// either is flat).
fn patch_correlation(img: &Gray<'_>, a: [isize; 2], b: [isize; 2], half: isize) -> f64 {
    let (mut sa, mut sb, mut saa, mut sbb, mut sab) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for dy in -half..=half {
        for dx in -half..=half {
            let x = f64::from(img.at((a[0] + dx) as usize, (a[1] + dy) as usize));
            let y = f64::from(img.at((b[0] + dx) as usize, (b[1] + dy) as usize));
            (sa, sb, saa, sbb, sab) = (sa + x, sb + y, saa + x * x, sbb + y * y, sab + x * y);
        }
    }
    let n = ((2 * half + 1) * (2 * half + 1)) as f64;
    let (va, vb) = (saa - sa * sa / n, sbb - sb * sb / n);
    if va <= 0.0 || vb <= 0.0 {
        return 0.0;
    }
    (sab - sa * sb / n) / (va * vb).sqrt()
}
