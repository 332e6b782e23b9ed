//! The correlation cross-sum `Σ P (T - 128)` for every placement, on each [`Path`]: AVX-512
//! VNNI (`vpdpbusd`, 64 byte products an instruction), AVX2 (`vpmaddwd` on zero-extended pixel
//! pairs, exact: no 16-bit saturation), NEON (`smlal`, pixels widened to 16 bits and multiplied
//! into 32-bit sums), and portable Rust (`cross/portable.rs`, which LLVM turns into `pmaddwd`
//! on baseline x86-64). All are exact integer sums, so they agree bit for bit; `nc.rs` calls
//! [`cross`].
//!
//! Layout (shared with `nc.rs`): `pad` holds the window's rows, `pw` bytes apart, padded with
//! zeros so whole blocks can be read past the last placement; `out` has a row stride of `nx`
//! rounded up to [`BLOCK_X`] and `ny` rounded up to [`BLOCK_Y`] rows.

#[cfg(target_arch = "aarch64")]
use core::arch::aarch64::*;
#[cfg(target_arch = "x86_64")]
use core::arch::x86_64::*;

use crate::simd::Path;

mod portable;
use portable::{Wide, cross_portable, widen};

/// Placements per block along a row.
pub(crate) const BLOCK_X: usize = 16;
/// Rows of placements per block.
pub(crate) const BLOCK_Y: usize = 4;

/// A template as the cross-sum kernels read it: `T - 128` as signed bytes.
#[derive(Debug, Clone, Default)]
pub(crate) struct Packed {
    /// Rows padded to a multiple of 4 bytes with zeros, packed 4 to an i32 (little-endian).
    pub(crate) quads: Vec<i32>,
    /// i32 groups of 4 per row.
    pub(crate) groups: usize,
    /// Rows padded to a multiple of 2 with zeros, each pair as two i16 in an i32.
    pub(crate) pairs: Vec<i32>,
    /// Pairs per row.
    pub(crate) npairs: usize,
    /// Each pair replicated over eight placements' lanes, column by column, for the portable
    /// kernel (`cross/portable.rs`).
    pub(crate) wide: Vec<Wide>,
    /// Template rows.
    pub(crate) rows: usize,
}

impl Packed {
    /// Packs the `w x h` template `data`, reusing the buffers.
    pub(crate) fn set(&mut self, data: &[u8], w: usize, h: usize) {
        let (groups, npairs) = (w.div_ceil(4), w.div_ceil(2));
        self.quads.clear();
        self.quads.resize(groups * h, 0);
        self.pairs.clear();
        self.pairs.resize(npairs * h, 0);
        for y in 0..h {
            for x in 0..w {
                let v = i32::from(data[y * w + x]) - 128;
                self.quads[y * groups + x / 4] |= i32::from(v as i8 as u8) << (8 * (x % 4));
                self.pairs[y * npairs + x / 2] |= i32::from(v as i16 as u16) << (16 * (x % 2));
            }
        }
        widen(&self.pairs, npairs, h, &mut self.wide);
        (self.groups, self.npairs, self.rows) = (groups, npairs, h);
    }
}

/// `Σ P (T - 128)` for the placements of `blocks`, into `out`, on `path` (which the CPU must
/// have: it is lowered to the fastest it has otherwise). A block is [`BLOCK_X`] x [`BLOCK_Y`]
/// placements, numbered row-major (`nx.div_ceil(BLOCK_X)` to a row); the rest of `out` is left
/// as it was.
///
/// `pad` must hold, past the last row of placements of any block, `t.rows + 4` rows of `pw`
/// bytes, with `pw >= ` `nx` rounded up to [`BLOCK_X`] plus `4 * t.groups + 32`; `out` must
/// hold every block's rows of `nx` rounded up to [`BLOCK_X`].
pub(crate) fn cross(
    path: Path,
    pad: &[u8],
    pw: usize,
    nx: usize,
    t: &Packed,
    blocks: &[u32],
    out: &mut [i32],
) {
    let stride = nx.next_multiple_of(BLOCK_X);
    let end = blocks.iter().map(|&b| origin(b as usize, nx).0 + BLOCK_Y).max().unwrap_or(0);
    let fits =
        pad.len() >= (end + t.rows + 4) * pw && pw >= stride + 4 * t.groups + 32 && out.len() >= end * stride;
    assert!(fits, "cross-sum buffers smaller than their contract");
    match Path::clamp(path) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has the path's features (clamped), and the sizes are checked above.
        Path::Avx512 => unsafe { cross_avx512(pad, pw, nx, t, blocks, out) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Path::Avx2 => unsafe { cross_avx2(pad, pw, nx, t, blocks, out) },
        #[cfg(target_arch = "aarch64")]
        // SAFETY: as above.
        Path::Neon => unsafe { cross_neon(pad, pw, nx, t, blocks, out) },
        _ => cross_portable(pad, pw, nx, t, blocks, out),
    }
}

/// Blocks of 16 placements x 4 rows at once. Each image row's bytes are gathered once per
/// 4-column template group into "sliding dwords" (lane `j` holds bytes `x + j .. x + j + 4`)
/// and multiplied by the template's group with `vpdpbusd`, for every output row that template
/// row reaches.
///
/// # Safety
/// The CPU must have AVX-512 F, BW and VNNI; sizes as [`cross`] checks them.
#[multiversion::target("x86_64+avx2+avx512f+avx512bw+avx512vnni")]
unsafe fn cross_avx512(pad: &[u8], pw: usize, nx: usize, t: &Packed, blocks: &[u32], out: &mut [i32]) {
    let (stride, groups, rows, packed) = (nx.next_multiple_of(BLOCK_X), t.groups, t.rows, &t.quads);
    let perm = _mm512_setr_epi32(0, 1, 2, 3, 1, 2, 3, 4, 2, 3, 4, 5, 3, 4, 5, 6);
    let shuf = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 1, 2, 3, 1, 2, 3, 4, 2, 3, 4, 5, 3, 4, 5, 6));
    for (y0, xb) in blocks.iter().map(|&b| origin(b as usize, nx)) {
        let mut acc = [_mm512_setzero_si512(); BLOCK_Y];
        for yy in 0..rows + 3 {
            // SAFETY: within `pad` by the size contract (row y0 + yy, bytes xb .. xb + 4 groups + 32).
            let base = unsafe { pad.as_ptr().add((y0 + yy) * pw + xb) };
            for g in 0..groups {
                // SAFETY: as above.
                let v = unsafe { _mm256_loadu_si256(base.add(4 * g) as *const __m256i) };
                let s = _mm512_shuffle_epi8(_mm512_permutexvar_epi32(perm, _mm512_castsi256_si512(v)), shuf);
                for (j, a) in acc.iter_mut().enumerate() {
                    let Some(r) = yy.checked_sub(j).filter(|r| *r < rows) else { continue };
                    *a = _mm512_dpbusd_epi32(*a, s, _mm512_set1_epi32(packed[r * groups + g]));
                }
            }
        }
        for (j, a) in acc.iter().enumerate() {
            // SAFETY: within `out` by the size contract.
            unsafe { _mm512_storeu_si512(out.as_mut_ptr().add((y0 + j) * stride + xb) as *mut __m512i, *a) };
        }
    }
}

/// Blocks of 16 placements (two vectors of 8) x 4 rows. For each pair of template columns, 16
/// image bytes are broadcast to both halves and shuffled into zero-extended pixel pairs (lane
/// `j` holds `p[x + j]`, `p[x + j + 1]` as two u16), and `vpmaddwd` with the template's pair (two
/// i16) adds both products into i32 lanes exactly.
///
/// # Safety
/// The CPU must have AVX2; sizes as [`cross`] checks them.
#[multiversion::target("x86_64+avx2+fma+bmi2")]
unsafe fn cross_avx2(pad: &[u8], pw: usize, nx: usize, t: &Packed, blocks: &[u32], out: &mut [i32]) {
    let (stride, npairs, rows, pairs) = (nx.next_multiple_of(BLOCK_X), t.npairs, t.rows, &t.pairs);
    let z = -1i8;
    #[rustfmt::skip]
    let shuf = _mm256_setr_epi8(
        0, z, 1, z, 1, z, 2, z, 2, z, 3, z, 3, z, 4, z,
        4, z, 5, z, 5, z, 6, z, 6, z, 7, z, 7, z, 8, z,
    );
    for (y0, xb) in blocks.iter().map(|&b| origin(b as usize, nx)) {
        let mut acc = [[_mm256_setzero_si256(); 2]; BLOCK_Y];
        for yy in 0..rows + 3 {
            // SAFETY: within `pad` by the size contract (row y0 + yy, bytes xb .. xb + 2 npairs + 24).
            let base = unsafe { pad.as_ptr().add((y0 + yy) * pw + xb) };
            for q in 0..npairs {
                // SAFETY: as above.
                let (lo, hi) = unsafe {
                    (
                        _mm_loadu_si128(base.add(2 * q) as *const __m128i),
                        _mm_loadu_si128(base.add(2 * q + 8) as *const __m128i),
                    )
                };
                let s0 = _mm256_shuffle_epi8(_mm256_broadcastsi128_si256(lo), shuf);
                let s1 = _mm256_shuffle_epi8(_mm256_broadcastsi128_si256(hi), shuf);
                for (j, a) in acc.iter_mut().enumerate() {
                    let Some(r) = yy.checked_sub(j).filter(|r| *r < rows) else { continue };
                    let tp = _mm256_set1_epi32(pairs[r * npairs + q]);
                    a[0] = _mm256_add_epi32(a[0], _mm256_madd_epi16(s0, tp));
                    a[1] = _mm256_add_epi32(a[1], _mm256_madd_epi16(s1, tp));
                }
            }
        }
        for (j, a) in acc.iter().enumerate() {
            // SAFETY: within `out` by the size contract.
            unsafe {
                let o = out.as_mut_ptr().add((y0 + j) * stride + xb);
                _mm256_storeu_si256(o as *mut __m256i, a[0]);
                _mm256_storeu_si256(o.add(8) as *mut __m256i, a[1]);
            }
        }
    }
}

/// Blocks of 16 placements (four vectors of 4) x 4 rows. For each template column, 16 image
/// bytes are loaded once per image row, widened to 16 bits, and `smlal` multiplies them by the
/// template's value into 32-bit lanes (exact: the product is formed at 32 bits), for every
/// output row that template row reaches.
///
/// # Safety
/// The CPU must have NEON; sizes as [`cross`] checks them.
#[cfg(target_arch = "aarch64")]
#[target_feature(enable = "neon")]
unsafe fn cross_neon(pad: &[u8], pw: usize, nx: usize, t: &Packed, blocks: &[u32], out: &mut [i32]) {
    let (stride, npairs, rows, pairs) = (nx.next_multiple_of(BLOCK_X), t.npairs, t.rows, &t.pairs);
    for (y0, xb) in blocks.iter().map(|&b| origin(b as usize, nx)) {
        let mut acc = [[vdupq_n_s32(0); 4]; BLOCK_Y];
        for yy in 0..rows + 3 {
            // SAFETY: within `pad` by the size contract (row y0 + yy, bytes xb .. xb + 2 npairs + 16).
            let base = unsafe { pad.as_ptr().add((y0 + yy) * pw + xb) };
            for c in 0..2 * npairs {
                // SAFETY: as above.
                let v = unsafe { vld1q_u8(base.add(c)) };
                let lo = vreinterpretq_s16_u16(vmovl_u8(vget_low_u8(v)));
                let hi = vreinterpretq_s16_u16(vmovl_high_u8(v));
                for (j, a) in acc.iter_mut().enumerate() {
                    let Some(r) = yy.checked_sub(j).filter(|r| *r < rows) else { continue };
                    let tv = (pairs[r * npairs + c / 2] >> (16 * (c % 2))) as i16;
                    a[0] = vmlal_n_s16(a[0], vget_low_s16(lo), tv);
                    a[1] = vmlal_high_n_s16(a[1], lo, tv);
                    a[2] = vmlal_n_s16(a[2], vget_low_s16(hi), tv);
                    a[3] = vmlal_high_n_s16(a[3], hi, tv);
                }
            }
        }
        for (j, a) in acc.iter().enumerate() {
            for (k, v) in a.iter().enumerate() {
                // SAFETY: within `out` by the size contract.
                unsafe { vst1q_s32(out.as_mut_ptr().add((y0 + j) * stride + xb + 4 * k), *v) };
            }
        }
    }
}

/// The first row and column of placements of block `b`.
#[inline(always)]
pub(crate) fn origin(b: usize, nx: usize) -> (usize, usize) {
    let per_row = nx.div_ceil(BLOCK_X);
    (b / per_row * BLOCK_Y, b % per_row * BLOCK_X)
}

/// `Σ P (T - 128)` of the one placement at column `x`, row `y` of `pad` (the same integer as
/// the kernels give it).
pub(crate) fn cross_one(pad: &[u8], pw: usize, t: &Packed, x: usize, y: usize) -> i32 {
    let mut acc = 0i32;
    for r in 0..t.rows {
        let row = &pad[(y + r) * pw + x..];
        for (q, &word) in t.pairs[r * t.npairs..(r + 1) * t.npairs].iter().enumerate() {
            acc += i32::from(row[2 * q]) * i32::from(word as i16);
            acc += i32::from(row[2 * q + 1]) * i32::from((word >> 16) as i16);
        }
    }
    acc
}
