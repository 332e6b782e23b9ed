//! Optical blur: a separable box filter over an interleaved 8-bit image, edges clamped.

/// The largest radius [`box_blur`] takes (the world's `blur_px` is at most 16).
const MAX_RADIUS: usize = 31;

/// Blurs `pixels` (`width x height`, `bpp` channels) in place with a `(2r + 1)`-pixel box
/// (`r` at most 31). Allocates nothing: each row and column is filtered in place.
pub fn box_blur(width: usize, height: usize, bpp: usize, r: usize, pixels: &mut [u8]) {
    if r == 0 || r > MAX_RADIUS || width == 0 || height == 0 || pixels.len() < width * height * bpp {
        return;
    }
    for y in 0..height {
        for c in 0..bpp {
            pass(pixels, (y * width) * bpp + c, bpp, width, r);
        }
    }
    for x in 0..width {
        for c in 0..bpp {
            pass(pixels, x * bpp + c, width * bpp, height, r);
        }
    }
}

/// The box mean of radius `r` over the `n` samples `px[start + k * stride]`, in place, by a
/// running sum (edges clamped). The originals the sum still needs after they are overwritten
/// (the last `2r + 1`) are kept in a ring.
fn pass(px: &mut [u8], start: usize, stride: usize, n: usize, r: usize) {
    let at = |k: usize| start + k * stride;
    let width = 2 * r + 1;
    let first = px[at(0)];
    let mut ring = [0u8; 2 * MAX_RADIUS + 1];
    let clamped = |px: &[u8], k: isize| u32::from(px[at(k.clamp(0, n as isize - 1) as usize)]);
    let mut sum: u32 = (-(r as isize)..=r as isize).map(|k| clamped(px, k)).sum();
    for i in 0..n {
        ring[i % width] = px[at(i)];
        px[at(i)] = ((sum + width as u32 / 2) / width as u32) as u8;
        if i + 1 == n {
            break;
        }
        // Entering: not yet overwritten (it is ahead of `i`, or the last sample, clamped).
        sum += u32::from(px[at((i + r + 1).min(n - 1))]);
        // Leaving: overwritten already, so from the ring (or the first sample, clamped).
        sum -= u32::from(if i < r { first } else { ring[(i - r) % width] });
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

    /// The box mean written out: each pass from a copy, every window summed afresh.
    fn reference(width: usize, height: usize, bpp: usize, r: usize, px: &mut [u8]) {
        let mean = |get: &dyn Fn(isize) -> u8, i: isize| {
            let sum: u32 = (i - r as isize..=i + r as isize).map(|k| u32::from(get(k))).sum();
            let w = 2 * r as u32 + 1;
            ((sum + w / 2) / w) as u8
        };
        let src = px.to_vec();
        for (y, x, c) in
            (0..height).flat_map(|y| (0..width).flat_map(move |x| (0..bpp).map(move |c| (y, x, c))))
        {
            let get = |k: isize| src[(y * width + k.clamp(0, width as isize - 1) as usize) * bpp + c];
            px[(y * width + x) * bpp + c] = mean(&get, x as isize);
        }
        let src = px.to_vec();
        for (y, x, c) in
            (0..height).flat_map(|y| (0..width).flat_map(move |x| (0..bpp).map(move |c| (y, x, c))))
        {
            let get = |k: isize| src[(k.clamp(0, height as isize - 1) as usize * width + x) * bpp + c];
            px[(y * width + x) * bpp + c] = mean(&get, y as isize);
        }
    }

    #[test]
    fn the_in_place_running_sum_is_the_box_mean() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for (width, height, bpp, r) in
            [(17, 9, 3, 1), (5, 40, 1, 3), (3, 2, 1, 4), (33, 21, 3, 16), (1, 1, 1, 2)]
        {
            let img: Vec<u8> = (0..width * height * bpp)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state >> 24) as u8
                })
                .collect();
            let (mut fast, mut slow) = (img.clone(), img);
            box_blur(width, height, bpp, r, &mut fast);
            reference(width, height, bpp, r, &mut slow);
            assert_eq!(fast, slow, "{width}x{height}x{bpp}, r {r}");
        }
    }
}
