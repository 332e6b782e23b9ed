//! A sidewalk drawn in perspective, for path following (tests and the kernels bench).

use harvey_vision::GrayBuf;

/// A bright path between dark verges, edges from the vanishing point `(vx, 200)` to `xl` and
/// `xr` on the bottom row of a 640x480 image, anti-aliased; `hide_right` paints the right verge
/// over the path.
#[allow(dead_code)] // the bench draws other sizes
pub fn path(vx: f32, xl: f32, xr: f32, hide_right: bool) -> GrayBuf {
    sidewalk([640, 480], [vx, 200.0], xl, xr, hide_right)
}

/// [`path`] in an image of `size`, vanishing at `vp`.
pub fn sidewalk(size: [usize; 2], vp: [f32; 2], xl: f32, xr: f32, hide_right: bool) -> GrayBuf {
    let ([vx, vy], bottom) = (vp, size[1] as f32);
    let inside = |x: f32, y: f32| {
        if y <= vy {
            return false;
        }
        let t = (y - vy) / (bottom - vy);
        let (l, r) = (vx + t * (xl - vx), vx + t * (xr - vx));
        x > l && (x < r || hide_right)
    };
    GrayBuf::from_fn(size[0], size[1], |x, y| {
        let n = (0..16)
            .filter(|k| {
                inside(x as f32 + (k % 4) as f32 / 4.0 + 0.125, y as f32 + (k / 4) as f32 / 4.0 + 0.125)
            })
            .count();
        let texture = (x * 7 + y * 13) % 5;
        (50 + texture + n * 130 / 16) as u8
    })
}
