//! The portable form of the Moravec peak search's row pass (the SIMD forms are in
//! `peaks_simd.rs`), plain Rust shaped for the SSE2 baseline: the row-window maxima by doubling
//! spans (the maxima over 2, 4, ... pixels, then two overlapping spans cover the window), each
//! a whole-row loop LLVM vectorises, and the tops looked for only in blocks that have one.
//!
//! An interest is at most 81 * 255² (23 bits), so maxima and the threshold's comparison are
//! taken as `i32`: SSE2 compares signed 32-bit lanes (`pcmpgtd`) but not unsigned ones.

/// Pixels per block searched for tops: two SSE2 registers of 32-bit lanes.
const BLOCK: usize = 8;

/// The larger of two interests (as `i32`, exact below 2³¹).
#[inline(always)]
fn max(p: u32, q: u32) -> u32 {
    (p as i32).max(q as i32) as u32
}

/// `dst[x]` = `max(src[x], src[x + span])` for `x < len`.
#[inline(always)]
fn double(dst: &mut Vec<u32>, src: &[u32], span: usize, len: usize) {
    dst.clear();
    dst.extend(src[..len].iter().zip(&src[span..span + len]).map(|(&p, &q)| max(p, q)));
}

/// `across[x]` = the maxima of padded row `row` over `x ..= x + 2r`, and every `x` at or
/// above `threshold` that equals it appended to `tops`; `spans` is scratch.
pub(super) fn scan_portable(
    row: &[u32],
    r: usize,
    threshold: u32,
    across: &mut [u32],
    tops: &mut Vec<u32>,
    spans: &mut [Vec<u32>; 2],
) {
    let (ww, taps) = (across.len(), 2 * r + 1);
    let [a, b] = spans;
    // `a` holds the maxima over `span` pixels, `ww + taps - span` of them (`row` itself at 1).
    let mut span = 1;
    while 2 * span <= taps {
        let len = ww + taps - 2 * span;
        if span == 1 {
            double(a, row, 1, len);
        } else {
            double(b, a, span, len);
            std::mem::swap(a, b);
        }
        span *= 2;
    }
    let spanned: &[u32] = if span == 1 { row } else { a };
    // The window `x ..= x + 2r` is the span at `x` and the one ending at `x + 2r`.
    let rest = &spanned[taps - span..][..ww];
    for ((o, &p), &q) in across.iter_mut().zip(spanned).zip(rest) {
        *o = max(p, q);
    }
    let centre = &row[r..r + ww];
    let t = threshold.min(i32::MAX as u32) as i32;
    let top = |v: u32, m: u32| v as i32 >= t && v == m;
    let (cs, _) = centre.as_chunks::<BLOCK>();
    let (ms, _) = across.as_chunks::<BLOCK>();
    for (i, (c, m)) in cs.iter().zip(ms).enumerate() {
        let any = c.iter().zip(m).fold(false, |any, (&v, &m)| any | top(v, m));
        if any {
            let x0 = i * BLOCK;
            tops.extend((0..BLOCK).filter(|&j| top(c[j], m[j])).map(|j| (x0 + j) as u32));
        }
    }
    let whole = cs.len() * BLOCK;
    tops.extend((whole..ww).filter(|&x| top(centre[x], across[x])).map(|x| x as u32));
}
