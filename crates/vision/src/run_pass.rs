//! Run extraction, the part of [`Runs::build`](crate::regions::Runs::build) that reads every
//! label: each row's maximal runs of one non-zero class, left to right, rows top to bottom. One
//! body compiled for each [`Path`] (the same runs on all): per row the classes are taken from
//! their nibble into a scratch row (a vectorised pass), and each chunk of [`CHUNK`] classes that
//! all continue the current run (background or a class) is passed over with one vectorised
//! compare; only the other chunks are looked at column by column.

use crate::regions::Run;
use crate::simd::Path;

/// Columns compared at once where nothing changes.
const CHUNK: usize = 32;

/// Where the runs come from: a `w x h` label image, each label's class in its `high` or low
/// nibble.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Labels<'a> {
    pub data: &'a [u8],
    pub w: usize,
    pub h: usize,
    pub high: bool,
}

/// Appends the runs of `labels` to `runs` (after clearing it) and each row's first run index to
/// `rows` (`h + 1` entries, the last the run count), on `path`; `scratch` is reused.
pub(crate) fn extract(
    path: Path,
    labels: Labels<'_>,
    scratch: &mut Vec<u8>,
    runs: &mut Vec<Run>,
    rows: &mut Vec<u32>,
) {
    runs.clear();
    rows.clear();
    scratch.clear();
    scratch.resize(labels.w, 0);
    match path {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the path is one the CPU has (callers clamp it or take `Path::active`).
        Path::Avx512 => unsafe { extract_avx512(labels, scratch, runs, rows) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Path::Avx2 => unsafe { extract_avx2(labels, scratch, runs, rows) },
        _ => extract_rows(labels, scratch, runs, rows),
    }
}

/// The one body: every row's runs.
#[inline(always)]
fn extract_rows(labels: Labels<'_>, cls: &mut [u8], runs: &mut Vec<Run>, rows: &mut Vec<u32>) {
    let w = labels.w;
    for y in 0..labels.h {
        rows.push(runs.len() as u32);
        let row = &labels.data[y * w..(y + 1) * w];
        if labels.high {
            cls.iter_mut().zip(row).for_each(|(c, &b)| *c = b >> 4);
        } else {
            cls.iter_mut().zip(row).for_each(|(c, &b)| *c = b & 0x0f);
        }
        let (mut x, mut x0, mut cur) = (0, 0, 0u8);
        while x < w {
            // A chunk is tested once: if it does not all continue the run, it is walked through.
            let end = (x + CHUNK).min(w);
            if end - x == CHUNK && continues(&cls[x..end], cur) {
                x = end;
                continue;
            }
            for (i, &c) in cls[x..end].iter().enumerate() {
                if c != cur {
                    if cur != 0 {
                        runs.push(Run {
                            y: y as u32,
                            x0: x0 as u32,
                            x1: (x + i) as u32,
                            class: cur,
                            region: 0,
                        });
                    }
                    (x0, cur) = (x + i, c);
                }
            }
            x = end;
        }
        if cur != 0 {
            runs.push(Run { y: y as u32, x0: x0 as u32, x1: w as u32, class: cur, region: 0 });
        }
    }
    rows.push(runs.len() as u32);
}

/// Whether every class of `chunk` is `c` (no early exit: one vector compare).
#[inline(always)]
fn continues(chunk: &[u8], c: u8) -> bool {
    chunk.iter().fold(0u8, |a, &b| a | (b ^ c)) == 0
}

/// [`extract_rows`] compiled for AVX-512.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx512`].
#[multiversion::target("x86_64+avx2+fma+bmi2+avx512f+avx512bw+avx512vnni")]
unsafe fn extract_avx512(labels: Labels<'_>, cls: &mut [u8], runs: &mut Vec<Run>, rows: &mut Vec<u32>) {
    extract_rows(labels, cls, runs, rows)
}

/// [`extract_rows`] compiled for AVX2.
///
/// # Safety
/// The CPU must have the features of [`Path::Avx2`].
#[multiversion::target("x86_64+avx2+fma+bmi2")]
unsafe fn extract_avx2(labels: Labels<'_>, cls: &mut [u8], runs: &mut Vec<Run>, rows: &mut Vec<u32>) {
    extract_rows(labels, cls, runs, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition: every maximal run of one non-zero class, pixel by pixel.
    fn plain(labels: Labels<'_>) -> Vec<Run> {
        let mut out = Vec::new();
        for y in 0..labels.h {
            let class = |x: usize| {
                let b = labels.data[y * labels.w + x];
                if labels.high { b >> 4 } else { b & 0x0f }
            };
            let mut x = 0;
            while x < labels.w {
                let (x0, c) = (x, class(x));
                while x < labels.w && class(x) == c {
                    x += 1;
                }
                if c != 0 {
                    out.push(Run { y: y as u32, x0: x0 as u32, x1: x as u32, class: c, region: 0 });
                }
            }
        }
        out
    }

    #[test]
    fn every_path_finds_the_plain_runs_on_odd_widths() {
        for (w, h) in [(1, 5), (15, 9), (17, 4), (31, 3), (33, 6), (641, 7)] {
            // Long runs, background stretches and every nibble, from a hash of the position.
            let data: Vec<u8> = (0..w * h)
                .map(|i| {
                    let z = ((i / 37) as u32).wrapping_mul(2_654_435_761) >> 24;
                    if z.is_multiple_of(3) { 0 } else { (z as u8).wrapping_mul(((i % 5) as u8) | 1) }
                })
                .collect();
            for high in [false, true] {
                let labels = Labels { data: &data, w, h, high };
                let want = plain(labels);
                for path in Path::available() {
                    let (mut s, mut runs, mut rows) = (Vec::new(), Vec::new(), Vec::new());
                    extract(path, labels, &mut s, &mut runs, &mut rows);
                    assert_eq!(runs, want, "{path}, {w}x{h}, high {high}");
                    assert_eq!(rows.len(), h + 1);
                    assert_eq!(rows.last().copied(), Some(runs.len() as u32));
                }
            }
        }
    }
}
