//! AVX-512 VNNI kernels, chosen at run time where the CPU has them; each has a portable twin
//! that tests compare it with.

#[cfg(target_arch = "x86_64")]
use core::arch::x86_64::*;

/// `Σ P (T - 128)` for blocks of 16 placements x 4 rows at once. Each image row's bytes are
/// gathered once per 4-column template group into "sliding dwords" (lane `j` holds bytes
/// `x + j .. x + j + 4`) and multiplied by the template's group with `vpdpbusd`, for every output
/// row that template row reaches.
///
/// # Safety
/// The CPU must have AVX-512 F, BW and VNNI. `pad` must hold `ny` rounded up to 4, plus `rows`
/// plus 4, rows of `pw` bytes, with `pw >= nx` rounded up to 16 plus `4 * groups + 32`; `out`
/// must hold `ny` rounded up to 4 rows of `nx` rounded up to 16.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512vnni")]
#[allow(clippy::too_many_arguments)]
pub(crate) unsafe fn cross_avx512(
    pad: &[u8],
    pw: usize,
    nx: usize,
    ny: usize,
    packed: &[i32],
    groups: usize,
    rows: usize,
    out: &mut [i32],
) {
    let stride = nx.next_multiple_of(16);
    let perm = _mm512_setr_epi32(0, 1, 2, 3, 1, 2, 3, 4, 2, 3, 4, 5, 3, 4, 5, 6);
    let shuf = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 1, 2, 3, 1, 2, 3, 4, 2, 3, 4, 5, 3, 4, 5, 6));
    debug_assert!(pad.len() >= (ny.next_multiple_of(4) + rows + 4) * pw);
    debug_assert!(out.len() >= ny.next_multiple_of(4) * stride);
    for y0 in (0..ny).step_by(4) {
        for xb in (0..nx).step_by(16) {
            let mut acc = [_mm512_setzero_si512(); 4];
            for yy in 0..rows + 3 {
                // SAFETY: within `pad` by the size contract (row y0 + yy, bytes xb .. xb + 4 groups + 32).
                let base = unsafe { pad.as_ptr().add((y0 + yy) * pw + xb) };
                for g in 0..groups {
                    // SAFETY: as above.
                    let v = unsafe { _mm256_loadu_si256(base.add(4 * g) as *const __m256i) };
                    let s =
                        _mm512_shuffle_epi8(_mm512_permutexvar_epi32(perm, _mm512_castsi256_si512(v)), shuf);
                    for (j, a) in acc.iter_mut().enumerate() {
                        let Some(r) = yy.checked_sub(j).filter(|r| *r < rows) else { continue };
                        *a = _mm512_dpbusd_epi32(*a, s, _mm512_set1_epi32(packed[r * groups + g]));
                    }
                }
            }
            for (j, a) in acc.iter().enumerate() {
                // SAFETY: within `out` by the size contract.
                unsafe {
                    _mm512_storeu_si512(out.as_mut_ptr().add((y0 + j) * stride + xb) as *mut __m512i, *a)
                };
            }
        }
    }
}
