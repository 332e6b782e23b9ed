//! Optical blur: a separable box filter over an interleaved 8-bit image, edges clamped.

/// Blurs `pixels` (`width x height`, `bpp` channels) in place with a `(2r + 1)`-pixel box.
pub fn box_blur(width: usize, height: usize, bpp: usize, r: usize, pixels: &mut [u8]) {
    if r == 0 || width == 0 || height == 0 || pixels.len() < width * height * bpp {
        return;
    }
    let mut line = Vec::with_capacity(width.max(height));
    for y in 0..height {
        for c in 0..bpp {
            let idx = |x: usize| (y * width + x) * bpp + c;
            pass(width, r, &mut line, |x| pixels[idx(x)]);
            for (x, &v) in line.iter().enumerate() {
                pixels[idx(x)] = v;
            }
        }
    }
    for x in 0..width {
        for c in 0..bpp {
            let idx = |y: usize| (y * width + x) * bpp + c;
            pass(height, r, &mut line, |y| pixels[idx(y)]);
            for (y, &v) in line.iter().enumerate() {
                pixels[idx(y)] = v;
            }
        }
    }
}

/// The box mean of radius `r` of the `n` samples `at(0..n)` into `out`, by a running sum.
fn pass(n: usize, r: usize, out: &mut Vec<u8>, at: impl Fn(usize) -> u8) {
    out.clear();
    let clamp = |i: isize| at(i.clamp(0, n as isize - 1) as usize);
    let width = 2 * r as isize + 1;
    let mut sum: u32 = (-(r as isize)..=r as isize).map(|i| u32::from(clamp(i))).sum();
    for i in 0..n as isize {
        out.push(((sum + width as u32 / 2) / width as u32) as u8);
        sum += u32::from(clamp(i + r as isize + 1));
        sum -= u32::from(clamp(i - r as isize));
    }
}

#[cfg(test)]
mod tests {
    use super::box_blur;

    #[test]
    fn a_step_edge_spreads_over_the_box_and_flat_areas_stay() {
        // A vertical edge: columns 0..4 at 0, 4..8 at 240.
        let mut img: Vec<u8> = (0..8 * 3).map(|i| if i % 8 < 4 { 0 } else { 240 }).collect();
        box_blur(8, 3, 1, 1, &mut img);
        assert_eq!(&img[..8], &[0, 0, 0, 80, 160, 240, 240, 240]);
        assert_eq!(&img[8..16], &img[..8], "rows alike: the vertical pass changes nothing");
        let mut flat = vec![90u8; 5 * 5 * 3];
        box_blur(5, 5, 3, 2, &mut flat);
        assert!(flat.iter().all(|&p| p == 90));
    }
}
