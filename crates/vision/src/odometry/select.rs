//! Picking features worth matching (003: "pick better features to match"): the Moravec operator
//! answers to edges that run between its four shift directions as well as to corners, and a
//! point on an edge slides along it in a search band (or in the reacquisition box) to wherever
//! the correlation likes. A feature is kept only where the patch's gradients turn: the smaller
//! eigenvalue of its structure tensor (the sums of `Ix²`, `Ix Iy`, `Iy²`) is at least a fraction
//! of the larger. An edge in any direction has a ratio near 0, a corner or a blob near 1. The
//! sensor's noise adds the same gradient energy to both eigenvalues (a noisy edge would look
//! like a weak corner), so what noise of the frame's own sigma adds is taken off both first.

use crate::image::Gray;

/// The ratio of the smaller eigenvalue of the structure tensor of the `(2 half + 1)²` patch
/// centred on `(x, y)` to the larger, each less what noise of `noise_sd` grey levels adds (0
/// on a flat patch); `None` when the patch and its gradients do not fit in the image.
pub fn turn_ratio(img: &Gray<'_>, x: usize, y: usize, half: usize, noise_sd: f64) -> Option<f64> {
    if x < half + 1 || y < half + 1 || x + half + 1 >= img.width || y + half + 1 >= img.height {
        return None;
    }
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    for v in y - half..=y + half {
        for u in x - half..=x + half {
            // Sobel: a staircase (a slanted edge drawn pixel by pixel) reads as the edge it is.
            let at = |u: usize, v: usize| f64::from(img.at(u, v));
            let gx = at(u + 1, v - 1) + 2.0 * at(u + 1, v) + at(u + 1, v + 1)
                - at(u - 1, v - 1)
                - 2.0 * at(u - 1, v)
                - at(u - 1, v + 1);
            let gy = at(u - 1, v + 1) + 2.0 * at(u, v + 1) + at(u + 1, v + 1)
                - at(u - 1, v - 1)
                - 2.0 * at(u, v - 1)
                - at(u + 1, v - 1);
            (a, b, c) = (a + gx * gx, b + gx * gy, c + gy * gy);
        }
    }
    // A Sobel derivative of pixels with independent noise has a variance of 12 sigma².
    let n = ((2 * half + 1) * (2 * half + 1)) as f64 * 12.0 * noise_sd * noise_sd;
    let (mean, spread) = ((a + c) / 2.0, ((a - c) * (a - c) / 4.0 + b * b).sqrt());
    let (large, small) = (mean + spread - n, mean - spread - n);
    Some(if large > 0.0 { (small / large).max(0.0) } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::GrayBuf;

    #[test]
    fn corners_turn_and_slanted_edges_do_not() {
        // A bright quadrant (corner at 40, 30) and, below it, a slanted edge (5 degrees).
        let img = GrayBuf::from_fn(120, 100, |x, y| {
            let corner = x >= 40 && (30..50).contains(&y);
            let slanted = (y as f64) > 75.0 + 0.0875 * x as f64;
            if corner || slanted { 200 } else { 50 }
        });
        let v = img.view();
        let corner = turn_ratio(&v, 40, 30, 5, 0.0).expect("fits");
        let edge = turn_ratio(&v, 60, 80, 5, 0.0).expect("fits");
        assert!(corner > 0.3, "corner {corner}");
        assert!(edge < 0.05, "slanted edge {edge}");
        assert_eq!(turn_ratio(&v, 50, 10, 5, 0.0), Some(0.0), "flat");
        assert_eq!(turn_ratio(&v, 3, 50, 5, 0.0), None, "too near the edge");
        // Noise of 8 grey levels on the edge: a weak corner unless the noise is taken off.
        let noisy = GrayBuf::from_fn(120, 100, |x, y| {
            let z = ((x * 7919 + y * 104_729) % 251) as f64 / 250.0 - 0.5;
            (f64::from(v.at(x, y)) + 27.7 * z).clamp(0.0, 255.0) as u8
        });
        let raw = turn_ratio(&noisy.view(), 60, 80, 5, 0.0).expect("fits");
        let taken_off = turn_ratio(&noisy.view(), 60, 80, 5, 8.0).expect("fits");
        assert!(taken_off < raw && taken_off < 0.05, "raw {raw}, noise taken off {taken_off}");
    }
}
