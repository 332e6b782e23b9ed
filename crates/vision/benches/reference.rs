//! Straightforward reference implementations: the formulas as written, no reuse, no tricks. The
//! benchmark times each kernel against its reference in the same run.

use harvey_vision::{Gray, GrayBuf, Rect};

/// Normalised correlation (000 §5.4) placement by placement, each patch normalised by its sum.
pub fn nc_best(img: &Gray<'_>, win: Rect, t: &GrayBuf) -> (usize, usize, f64) {
    let st: f64 = t.data.iter().map(|&v| f64::from(v)).sum();
    let mut best = (0, 0, f64::MIN);
    for y in win.y0..=win.y1 - t.height {
        for x in win.x0..=win.x1 - t.width {
            let mut sp = 0.0;
            for r in 0..t.height {
                for c in 0..t.width {
                    sp += f64::from(img.at(x + c, y + r));
                }
            }
            let (mut pt, mut pp, mut tt) = (0.0, 0.0, 0.0);
            for r in 0..t.height {
                for c in 0..t.width {
                    let rp = f64::from(img.at(x + c, y + r)) / sp;
                    let rt = f64::from(t.data[r * t.width + c]) / st;
                    pt += rp * rt;
                    pp += rp * rp;
                    tt += rt * rt;
                }
            }
            let nc = 2.0 * pt / (pp + tt);
            if nc > best.2 {
                best = (x, y, nc);
            }
        }
    }
    best
}
