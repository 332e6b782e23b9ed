//! A vertical line's expected appearance (000 §5.3's templates, for a line): the step in
//! reflectance across it, right side less left, in a few bands of image rows, ray traced from a
//! believed pose. The Expecter sends it with a landmark's window, so that the recogniser can
//! tell the landmark's edge from a look-alike of the other polarity (one door's west jamb
//! beside another's east jamb).

use harvey_world::{Pose2, World};

use crate::reflectance_at;

/// Bands of rows the expected step is given in (`Expectation::contrast`).
pub const CONTRAST_BANDS: usize = 4;

/// Pixels either side of the line's column where its two sides are sampled: clear of a soft
/// lens's spread (a blur radius of 1-2 px) and of the column's rounding.
const SIDE_PX: f64 = 3.0;

/// The step in reflectance across image column `u`, right side less left, in
/// [`CONTRAST_BANDS`] equal bands of the rows `v0..v1`, top first, as the camera at `pose` sees
/// `world`: each band sampled at three rows (its quarter points and middle) and averaged.
pub fn edge_contrast(
    world: &World,
    pose: Pose2,
    (width_px, height_px): (u32, u32),
    u: f64,
    [v0, v1]: [f64; 2],
) -> [f32; CONTRAST_BANDS] {
    let band_rows = (v1 - v0) / CONTRAST_BANDS as f64;
    std::array::from_fn(|b| {
        let step: f64 = [0.25, 0.5, 0.75]
            .iter()
            .map(|f| {
                let v = v0 + (b as f64 + f) * band_rows;
                let at = |u| reflectance_at(world, pose, width_px, height_px, u, v);
                at(u + SIDE_PX) - at(u - SIDE_PX)
            })
            .sum();
        (step / 3.0) as f32
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_doors_two_jambs_step_opposite_ways() {
        let world = harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway")
            .expect("hallway loads");
        let (w, h) = (640, 480);
        // Looking down the hall from its west end: the lab door's jambs on the left.
        let pose = Pose2::new(0.0, 0.0, 0.0);
        let step = |x: f64| {
            let foot = world.camera.project(w, h, pose, [x, 1.0, 0.0]).expect("in view");
            let head = world.camera.project(w, h, pose, [x, 1.0, 2.1]).expect("in view");
            edge_contrast(&world, pose, (w, h), foot[0], [head[1], foot[1]])
        };
        let (west, east) = (step(4.0), step(4.9));
        // Left of the west jamb the corridor's wall (0.70), right of it the lab seen through
        // the door, darker: a step down to the right in every band. The east jamb the other way.
        assert!(west.iter().all(|&c| c < 0.0), "west {west:?}");
        assert!(east.iter().all(|&c| c > 0.0), "east {east:?}");
        // Beside the door, the wall's 0.70 against the lab's far wall (0.50).
        assert!((west[1] + 0.2).abs() < 1e-6 && (east[1] - 0.2).abs() < 1e-6, "{west:?} {east:?}");
    }
}
