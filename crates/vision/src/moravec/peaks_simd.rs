//! The SIMD forms of the Moravec peak search's row pass (the portable form is `scan_portable`
//! in `peaks_portable.rs`): the row-window maxima, and the pixels at or above the threshold that top
//! their row window, found sixteen (AVX-512) or eight (AVX2) at a time as a bit mask.

#[cfg(target_arch = "x86_64")]
use core::arch::x86_64::*;

use super::peaks_portable::scan_portable;
use crate::simd::Path;

/// Writes `across[x]`, the maxima of padded row `row` over `x ..= x + 2r` (the window round
/// pixel `x`), for the `across.len()` pixels, and appends to `tops` every `x` whose own value
/// is at or above `threshold` and equals that maximum, on `path` (lowered to one the CPU has);
/// `spans` is the portable form's scratch.
pub(super) fn scan(
    path: Path,
    row: &[u32],
    r: usize,
    threshold: u32,
    across: &mut [u32],
    tops: &mut Vec<u32>,
    spans: &mut [Vec<u32>; 2],
) {
    assert!(row.len() >= across.len() + 2 * r, "a padded row holds r zeros either side");
    match Path::clamp(path) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has the path's features (clamped); the row's length is asserted.
        Path::Avx512 => unsafe { scan_avx512(row, r, threshold, across, tops) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Path::Avx2 => unsafe { scan_avx2(row, r, threshold, across, tops) },
        _ => scan_portable(row, r, threshold, across, tops, spans),
    }
}

/// [`scan`] with AVX-512: the common radii get their taps unrolled.
///
/// # Safety
/// The CPU must have AVX-512 F; `row.len() >= across.len() + 2r`.
#[multiversion::target("x86_64+avx2+avx512f")]
unsafe fn scan_avx512(row: &[u32], r: usize, threshold: u32, across: &mut [u32], tops: &mut Vec<u32>) {
    match r {
        1 => scan_taps::<3>(row, r, threshold, across, tops),
        2 => scan_taps::<5>(row, r, threshold, across, tops),
        3 => scan_taps::<7>(row, r, threshold, across, tops),
        4 => scan_taps::<9>(row, r, threshold, across, tops),
        _ => scan_taps::<0>(row, r, threshold, across, tops),
    }
}

/// [`scan`] with AVX2, eight pixels at a time; the last `len % 8` by the portable rule.
///
/// # Safety
/// The CPU must have AVX2; `row.len() >= across.len() + 2r`.
#[multiversion::target("x86_64+avx2+fma+bmi2")]
unsafe fn scan_avx2(row: &[u32], r: usize, threshold: u32, across: &mut [u32], tops: &mut Vec<u32>) {
    match r {
        1 => scan_taps8::<3>(row, r, threshold, across, tops),
        2 => scan_taps8::<5>(row, r, threshold, across, tops),
        3 => scan_taps8::<7>(row, r, threshold, across, tops),
        4 => scan_taps8::<9>(row, r, threshold, across, tops),
        _ => scan_taps8::<0>(row, r, threshold, across, tops),
    }
}

/// [`scan_avx2`] with `TAPS = 2r + 1` known (0: any `r`).
#[multiversion::target("x86_64+avx2+fma+bmi2")]
fn scan_taps8<const TAPS: usize>(
    row: &[u32],
    r: usize,
    threshold: u32,
    across: &mut [u32],
    tops: &mut Vec<u32>,
) {
    let ww = across.len();
    let taps = if TAPS == 0 { 2 * r + 1 } else { TAPS };
    let whole = ww - ww % 8;
    let src = row.as_ptr();
    // Unsigned `v >= t` as `max(v, t) == v`.
    let t = _mm256_set1_epi32(threshold as i32);
    for x in (0..whole).step_by(8) {
        // SAFETY (all loads): lanes `x + tap .. x + tap + 8` end at `whole - 1 + 2r`, inside the
        // padded row (asserted by `scan`).
        let load = |tap: usize| unsafe { _mm256_loadu_si256(src.add(x + tap).cast()) };
        let (mut even, mut odd) = (load(0), _mm256_setzero_si256());
        let mut tap = 1;
        while tap + 1 < taps {
            odd = _mm256_max_epu32(odd, load(tap));
            even = _mm256_max_epu32(even, load(tap + 1));
            tap += 2;
        }
        if tap < taps {
            odd = _mm256_max_epu32(odd, load(tap));
        }
        let acc = _mm256_max_epu32(even, odd);
        // SAFETY: lanes `x .. x + 8` are inside `across` (x + 8 <= whole <= ww).
        unsafe { _mm256_storeu_si256(across.as_mut_ptr().add(x).cast(), acc) };
        let v = load(r);
        let hit = _mm256_and_si256(_mm256_cmpeq_epi32(_mm256_max_epu32(v, t), v), _mm256_cmpeq_epi32(v, acc));
        let mut hits = _mm256_movemask_ps(_mm256_castsi256_ps(hit)) as u32;
        while hits != 0 {
            tops.push((x + hits.trailing_zeros() as usize) as u32);
            hits &= hits - 1;
        }
    }
    // The tail: the same rule, pixel by pixel.
    for x in whole..ww {
        let m = row[x..=x + 2 * r].iter().copied().max().unwrap_or(0);
        across[x] = m;
        let v = row[x + r];
        if v >= threshold && v == m {
            tops.push(x as u32);
        }
    }
}

/// [`scan`] with `TAPS = 2r + 1` known (0: any `r`).
#[multiversion::target("x86_64+avx2+avx512f")]
fn scan_taps<const TAPS: usize>(
    row: &[u32],
    r: usize,
    threshold: u32,
    across: &mut [u32],
    tops: &mut Vec<u32>,
) {
    let ww = across.len();
    let taps = if TAPS == 0 { 2 * r + 1 } else { TAPS };
    let (src, out) = (row.as_ptr(), across.as_mut_ptr());
    let t = _mm512_set1_epi32(threshold as i32);
    for x in (0..ww).step_by(16) {
        let k: __mmask16 = if ww - x >= 16 { 0xffff } else { (1 << (ww - x)) - 1 };
        // SAFETY (all loads): lanes `x + tap + i` for the first `ww - x` lanes end at
        // `ww - 1 + 2r`, inside the padded row (asserted by `scan`).
        let load = |tap: usize| unsafe {
            if k == 0xffff {
                _mm512_loadu_si512(src.add(x + tap).cast())
            } else {
                _mm512_maskz_loadu_epi32(k, src.add(x + tap).cast())
            }
        };
        // Two chains, so the maxima do not wait on each other.
        let (mut even, mut odd) = (load(0), _mm512_setzero_si512());
        let mut tap = 1;
        while tap + 1 < taps {
            odd = _mm512_max_epu32(odd, load(tap));
            even = _mm512_max_epu32(even, load(tap + 1));
            tap += 2;
        }
        if tap < taps {
            odd = _mm512_max_epu32(odd, load(tap));
        }
        let acc = _mm512_max_epu32(even, odd);
        // SAFETY: the first `ww - x` lanes are inside `across`.
        unsafe { _mm512_mask_storeu_epi32(out.add(x).cast(), k, acc) };
        let v = load(r);
        let mut hits = _mm512_mask_cmpge_epu32_mask(k, v, t) & _mm512_cmpeq_epi32_mask(v, acc);
        while hits != 0 {
            tops.push((x + hits.trailing_zeros() as usize) as u32);
            hits &= hits - 1;
        }
    }
}
