//! The portable cross-sum `Σ P (T - 128)`: plain safe Rust in the shape LLVM turns into
//! `pmaddwd` on baseline x86-64 (SSE2) and into widening multiply-adds on NEON.
//!
//! For each pair of template columns, the placements of a row need the pixel pairs `p[x + j]`,
//! `p[x + j + 1]` (two i16, lane `j`), each multiplied by the template's pair and the two
//! products added into an i32 lane: `pmaddwd`, exactly (pixels and `T - 128` both fit an i16;
//! the products and their sum are formed at 32 bits). The pixel pairs of a block's image rows
//! are laid out once per chunk of [`CHUNK`] template pairs and read by all four rows of
//! placements; the template's pairs come replicated over eight lanes ([`Packed::wide`]), so
//! each multiply is a whole vector by a whole vector and the pairwise add of its products is
//! what LLVM matches.
//!
//! The shape matters more than it should: the same arithmetic written as one loop over the
//! template's pairs, over sixteen lanes at once, or as four multiply-adds in one basic block
//! comes out as half-width `pmaddwd`s with masks and shifts, or as scalar code. Check the
//! assembly after changing it (`objdump -d` of the kernels bench, `portable5group`).

use super::{BLOCK_X, BLOCK_Y, Packed, origin};

/// Template pairs whose pixel pairs are laid out at once.
const CHUNK: usize = 8;
/// Pixel pairs of an image row that one chunk reads: the block's placements plus the chunk's
/// columns.
const SPAN: usize = BLOCK_X + 2 * CHUNK;
/// Image rows whose pixel pairs are laid out at once (a 16-row template's block needs 19).
const STRIP_ROWS: usize = 20;
/// Placements of a row taken at once: half a block, so that the sums of the block's four rows
/// (eight vectors of four i32 on SSE2) stay in registers.
const HALF: usize = BLOCK_X / 2;

/// The pixel pairs of [`HALF`] placements, or a template pair replicated over their lanes.
type Half = [i16; 2 * HALF];

/// A template pair replicated over the i16 lanes of [`HALF`] placements, aligned so that the
/// multiply-add can read it from memory.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(16))]
pub(crate) struct Wide(Half);

/// The replicated pairs of the template whose `rows` rows of `npairs` pairs are `pairs`, into
/// `wide`, column by column: pair `q` of row `r` at `q * rows + r`.
pub(crate) fn widen(pairs: &[i32], npairs: usize, rows: usize, wide: &mut Vec<Wide>) {
    wide.clear();
    for q in 0..npairs {
        for word in pairs.iter().skip(q).step_by(npairs).take(rows) {
            let pair = [*word as i16, (*word >> 16) as i16];
            wide.push(Wide(std::array::from_fn(|k| pair[k % 2])));
        }
    }
}

/// `Σ P (T - 128)` for the placements of `blocks` into `out` (layout and sizes as
/// [`super::cross`] checks them).
pub(crate) fn cross_portable(pad: &[u8], pw: usize, nx: usize, t: &Packed, blocks: &[u32], out: &mut [i32]) {
    let (stride, rows) = (nx.next_multiple_of(BLOCK_X), t.rows);
    let mut strip = [[0i16; 2 * SPAN]; STRIP_ROWS];
    for (y0, xb) in blocks.iter().map(|&b| origin(b as usize, nx)) {
        let mut acc = [[[0i32; HALF]; BLOCK_Y]; 2];
        for c0 in (0..t.npairs).step_by(CHUNK) {
            for g0 in (0..rows + BLOCK_Y - 1).step_by(STRIP_ROWS) {
                let g1 = (g0 + STRIP_ROWS).min(rows + BLOCK_Y - 1);
                // All the group's pixel pairs are written before any is read: a read then finds
                // them in the cache, not half in the store buffer.
                for (yy, px) in (g0..g1).zip(strip.iter_mut()) {
                    pixel_pairs(&pad[(y0 + yy) * pw + xb + 2 * c0..][..SPAN + 1], px);
                }
                for (h, acc) in acc.iter_mut().enumerate() {
                    for (q, col) in t.wide.chunks_exact(rows.max(1)).enumerate().skip(c0).take(CHUNK) {
                        let at = 4 * (q - c0) + 2 * HALF * h;
                        *acc = group(*acc, &strip[..g1 - g0], g0, col, at);
                    }
                }
            }
        }
        for (j, row) in out.chunks_mut(stride).skip(y0).take(BLOCK_Y).enumerate() {
            for (h, acc) in acc.iter().enumerate() {
                row[xb + HALF * h..][..HALF].copy_from_slice(&acc[j]);
            }
        }
    }
}

/// Adds one template pair's products over the image rows of a group (`strip`, the first
/// image row `g0`) into half a block's four rows of sums: image row `yy` reaches placement row
/// `j` through template row `r = yy - j`, whose replicated pair is `col[r]`; the pixel pairs
/// are the [`HALF`] pairs from `at` in each strip row. Not inlined, and nothing in it can
/// panic, so that the sums, taken and given back by value, stay in registers.
#[inline(never)]
fn group(
    sums: [[i32; HALF]; BLOCK_Y],
    strip: &[[i16; 2 * SPAN]],
    g0: usize,
    col: &[Wide],
    at: usize,
) -> [[i32; HALF]; BLOCK_Y] {
    // Local vectors, not the argument's memory (which LLVM would write back at every step).
    let [mut a0, mut a1, mut a2, mut a3] = sums;
    for (yy, row) in (g0..).zip(strip) {
        let Some(Ok(px)) = row.get(at..at + 2 * HALF).map(<&Half>::try_from) else { continue };
        for (j, a) in [&mut a0, &mut a1, &mut a2, &mut a3].into_iter().enumerate() {
            // Below row 0, `yy - j` wraps to an index past the end: one comparison for both.
            if let Some(t) = col.get(yy.wrapping_sub(j)) {
                madd(a, px, t);
            }
        }
    }
    [a0, a1, a2, a3]
}

/// `row[k]`, `row[k + 1]` as two i16 for each of the [`SPAN`] columns `k`.
#[inline(always)]
fn pixel_pairs(row: &[u8], px: &mut [i16; 2 * SPAN]) {
    for (k, pair) in px.chunks_exact_mut(2).enumerate() {
        pair[0] = i16::from(row[k]);
        pair[1] = i16::from(row[k + 1]);
    }
}

/// `acc[i] += p[2i] t[2i] + p[2i + 1] t[2i + 1]`, written as a whole-vector multiply and a
/// pairwise add of its products: the shape LLVM lowers to `pmaddwd`.
#[inline(always)]
fn madd(acc: &mut [i32; HALF], p: &Half, Wide(t): &Wide) {
    let mut prod = [0i32; 2 * HALF];
    for (k, v) in prod.iter_mut().enumerate() {
        *v = i32::from(p[k]) * i32::from(t[k]);
    }
    for (i, a) in acc.iter_mut().enumerate() {
        *a += prod[2 * i] + prod[2 * i + 1];
    }
}
