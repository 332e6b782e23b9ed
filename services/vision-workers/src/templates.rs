//! Appearance templates by ray tracing (000 §5.3): an `n x n` array centred on where a landmark
//! point projects from the expected pose, each pixel `255 R` for the reflectance `R` of the first
//! surface its ray meets. Matched by reflectance-normalised correlation (000 §5.4), a template
//! needs no model of the lighting.

use harvey_vision::{GrayBuf, Rect};
use harvey_world::{Pose2, World};

/// A template and where it sits in the image.
#[derive(Debug, Clone, PartialEq)]
pub struct AppearanceTemplate {
    pub pixels: GrayBuf,
    /// Top-left corner of the template in the image (pixels).
    pub origin: [usize; 2],
    /// Where the landmark point projects from the expected pose.
    pub projection: [f64; 2],
}

impl AppearanceTemplate {
    /// The template's own rectangle in the image.
    pub fn rect(&self) -> Rect {
        let [x, y] = self.origin;
        Rect::new(x, y, x + self.pixels.width, y + self.pixels.height)
    }
}

/// Builds the `side x side` template of world point `point_m` seen from `pose` in a
/// `width x height` image; `None` when the point is behind the camera or the template would
/// leave the image.
pub fn build(
    world: &World,
    pose: Pose2,
    point_m: [f64; 3],
    width: u32,
    height: u32,
    side: usize,
) -> Option<AppearanceTemplate> {
    let mut t = AppearanceTemplate { pixels: GrayBuf::default(), origin: [0, 0], projection: [0.0, 0.0] };
    build_into(&mut t, world, pose, point_m, [width, height], side).then_some(t)
}

/// [`build`] into `out`, reusing its pixels; false (and `out` unusable) when it cannot be built.
pub fn build_into(
    out: &mut AppearanceTemplate,
    world: &World,
    pose: Pose2,
    point_m: [f64; 3],
    [width, height]: [u32; 2],
    side: usize,
) -> bool {
    let Some([u, v]) = world.camera.project(width, height, pose, point_m) else { return false };
    let half = side as f64 / 2.0;
    let (x0, y0) = ((u - half).round(), (v - half).round());
    let fits = x0 >= 0.0
        && y0 >= 0.0
        && x0 + side as f64 <= f64::from(width)
        && y0 + side as f64 <= f64::from(height);
    if side == 0 || !fits {
        return false;
    }
    let (x0, y0) = (x0 as usize, y0 as usize);
    let px = &mut out.pixels;
    (px.width, px.height) = (side, side);
    px.data.clear();
    for j in 0..side {
        px.data.extend((0..side).map(|i| {
            let (pu, pv) = ((x0 + i) as f64 + 0.5, (y0 + j) as f64 + 0.5);
            let r = harvey_render::reflectance_at(world, pose, width, height, pu, pv);
            (255.0 * r).round().clamp(0.0, 255.0) as u8
        }));
    }
    (out.origin, out.projection) = ([x0, y0], [u, v]);
    true
}
