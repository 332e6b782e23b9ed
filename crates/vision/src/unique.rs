//! Whether a correlation's best match is unique: the best score away from it (a runner-up more
//! than `radius` placements off in either direction). A patch on an edge slides along the edge
//! and one on a repeated pattern matches each repeat nearly as well; the runner-up says so,
//! where a threshold on the best score alone takes the first such "near miss" (003).

use crate::image::{Gray, Rect, VisionError};
use crate::nc::{Correlator, Match, Template};

/// The highest score of `t` in `window` of `img` more than `radius` placements from `best`
/// (found in the same window); -1 when every placement lies within the radius.
pub fn runner_up(
    correlator: &mut Correlator,
    img: &Gray<'_>,
    window: Rect,
    t: &Template,
    best: &Match,
    radius: usize,
) -> Result<f32, VisionError> {
    let scores = correlator.correlate(img, window, t)?;
    // Placements per row, as `Correlator::placements` reports them.
    let nx = window.width() + 1 - t.width;
    let (bx, by) = (best.x - window.x0, best.y - window.y0);
    let far = |i: usize| (i % nx).abs_diff(bx) > radius || (i / nx).abs_diff(by) > radius;
    Ok(scores.iter().enumerate().filter(|(i, _)| far(*i)).map(|(_, s)| *s).fold(-1.0, f32::max))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::GrayBuf;

    #[test]
    fn an_edge_has_a_close_runner_up_and_a_corner_does_not() {
        // A bright quadrant: its corner at (40, 30), its edges running left and down from it.
        let img = GrayBuf::from_fn(80, 60, |x, y| if x >= 40 && y >= 30 { 200 } else { 50 });
        let mut c = Correlator::default();
        let check = |c: &mut Correlator, at: (usize, usize)| {
            let patch =
                GrayBuf::crop(&img.view(), Rect::new(at.0 - 4, at.1 - 4, at.0 + 5, at.1 + 5)).expect("crops");
            let t = Template::new(&patch).expect("a template");
            let window = Rect::new(20, 10, 70, 55);
            let best = c.best(&img.view(), window, &t).expect("found");
            (best.score, runner_up(c, &img.view(), window, &t, &best, 2).expect("scored"))
        };
        // At the corner, three pixels off loses a quarter of the patch's contrast: 0.9 at best.
        let (corner, second) = check(&mut c, (40, 30));
        assert!(corner > 0.99 && second < 0.92, "corner {corner}, runner-up {second}");
        // On the vertical edge below the corner, the patch matches as well further down.
        let (edge, second) = check(&mut c, (40, 45));
        assert!(edge > 0.99 && second > 0.99, "edge {edge}, runner-up {second}");
    }
}
