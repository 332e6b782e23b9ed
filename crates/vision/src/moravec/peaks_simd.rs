//! The AVX-512 form of the Moravec peak search's row pass (the portable form is
//! `Peaks::scan_portable` in `peaks.rs`): the row-window maxima, and the pixels at or above the
//! threshold that top their row window, found sixteen at a time as a bit mask.

#[cfg(target_arch = "x86_64")]
use core::arch::x86_64::*;

/// Whether the CPU has AVX-512 F (checked once and cached by the standard library).
#[cfg(target_arch = "x86_64")]
pub(super) fn available() -> bool {
    std::is_x86_feature_detected!("avx512f")
}

/// Writes `across[x]`, the maxima of padded row `row` over `x ..= x + 2r` (the window round
/// pixel `x`), for the `across.len()` pixels, and appends to `tops` every `x` whose own value
/// is at or above `threshold` and equals that maximum.
///
/// # Safety
/// The CPU must have AVX-512 F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn scan(row: &[u32], r: usize, threshold: u32, across: &mut [u32], tops: &mut Vec<u32>) {
    assert!(row.len() >= across.len() + 2 * r, "a padded row holds r zeros either side");
    // The common radii get their taps unrolled.
    match r {
        1 => scan_taps::<3>(row, r, threshold, across, tops),
        2 => scan_taps::<5>(row, r, threshold, across, tops),
        3 => scan_taps::<7>(row, r, threshold, across, tops),
        4 => scan_taps::<9>(row, r, threshold, across, tops),
        _ => scan_taps::<0>(row, r, threshold, across, tops),
    }
}

/// [`scan`] with `TAPS = 2r + 1` known (0: any `r`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
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
