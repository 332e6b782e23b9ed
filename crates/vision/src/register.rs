//! Registering a frame against the start of a depth-from-motion run (001 §2.3): the shift of
//! the whole image (a camera turned a little) that puts the tracked points back on their
//! radial lines from the focus of expansion.

/// The frame's shift: given each match's radial direction `d` (from the FOE to where the point
/// was) and its place `m` relative to the FOE in this frame, the shift `s` (within `reach` of
/// `guess`) that puts the matches back on their lines, `d × (m - s) = 0`, by least squares,
/// refitted without matches left more than 1.5 px off (a mismatch, a thing that moved). Points
/// spread round the FOE tie both directions down; with fewer than four matches, all along one
/// direction, or a solution beyond the reach, the last refit's shift stands (the guess, if
/// none was made).
pub fn register(lines: &[([f32; 2], [f32; 2])], guess: [f32; 2], reach: f32) -> [f32; 2] {
    let mut keep: Vec<bool> = vec![true; lines.len()];
    let mut shift = guess;
    for _ in 0..4 {
        // Normal n = (-d.y, d.x); n · (m - s) = 0 for every kept match.
        let (mut a, mut b) = ([[0.0f64; 2]; 2], [0.0f64; 2]);
        let mut n_kept = 0;
        for ((d, m), _) in lines.iter().zip(&keep).filter(|(_, k)| **k) {
            let n = [-f64::from(d[1]), f64::from(d[0])];
            let c = n[0] * f64::from(m[0]) + n[1] * f64::from(m[1]);
            for i in 0..2 {
                for j in 0..2 {
                    a[i][j] += n[i] * n[j];
                }
                b[i] += n[i] * c;
            }
            n_kept += 1;
        }
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        if n_kept < 4 || det < 0.05 * (a[0][0] + a[1][1]).powi(2) {
            return shift;
        }
        let s = [(b[0] * a[1][1] - b[1] * a[0][1]) / det, (a[0][0] * b[1] - a[1][0] * b[0]) / det];
        if (s[0] - f64::from(guess[0])).hypot(s[1] - f64::from(guess[1])) > f64::from(reach) {
            return shift;
        }
        shift = [s[0] as f32, s[1] as f32];
        let mut changed = false;
        for ((d, m), k) in lines.iter().zip(keep.iter_mut()) {
            let off = -d[1] * (m[0] - shift[0]) + d[0] * (m[1] - shift[1]);
            let fits = off.abs() <= 1.5;
            changed |= *k != fits;
            *k = fits;
        }
        if !changed {
            break;
        }
    }
    shift
}
