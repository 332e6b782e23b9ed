//! The apparent heights of the dock frame's end posts, for the inverse perspective of 004
//! §4.1.3: a frame turned away shows its far post shorter.

use crate::flf::Line;

/// How far (model units) from a post's column a line may end and still be taken at it.
const NEAR_POST: f32 = 0.25;
/// How far (model units) from the model's bar a bar's edge may lie.
const NEAR_BAR: f32 = 0.2;
/// Near-horizontal or near-vertical: within this many degrees.
const SQUARE_DEG: f32 = 10.0;

/// The apparent heights (pixels) of the frame's end posts, left then right, for a match at `at`
/// with `scale` pixels per model unit (the frame 2 x 1 units, its posts at +-1): the span at
/// each post's column between the top bar's upper edge and the bottom bar's lower edge, the
/// bars' edge lines extended to the column; where a bar's edge is not seen there, the longest
/// near-vertical line near the post (0 where neither is). The bars are long and unbroken, while
/// a post's outer edge breaks where the bars' ends meet it, leaving a line between the bars
/// (0.84 of the post's height in the dock world) as the longest.
pub fn post_heights(lines: &[Line], at: [f32; 2], scale: f32) -> [f32; 2] {
    let mut out = [0.0f32; 2];
    for (k, side) in [-1.0f32, 1.0].into_iter().enumerate() {
        let post_u = at[0] + side * scale;
        out[k] = between_bars(lines, at, scale, post_u)
            .unwrap_or_else(|| longest_post_line(lines, at, scale, post_u));
    }
    out
}

/// The span at column `post_u` from the uppermost edge near the top bar to the lowermost near
/// the bottom bar.
fn between_bars(lines: &[Line], at: [f32; 2], scale: f32, post_u: f32) -> Option<f32> {
    let (mut top, mut bottom) = (f32::INFINITY, f32::NEG_INFINITY);
    for l in lines {
        let o = l.orientation_deg;
        if o.min(180.0 - o) > SQUARE_DEG {
            continue;
        }
        let (u0, u1) = (l.from[0].min(l.to[0]), l.from[0].max(l.to[0]));
        if u0 > post_u + NEAR_POST * scale || u1 < post_u - NEAR_POST * scale || u1 - u0 < 1.0 {
            continue;
        }
        let t = (post_u - l.from[0]) / (l.to[0] - l.from[0]);
        let v = l.from[1] + t * (l.to[1] - l.from[1]);
        if (v - (at[1] - 0.5 * scale)).abs() < NEAR_BAR * scale {
            top = top.min(v);
        } else if (v - (at[1] + 0.5 * scale)).abs() < NEAR_BAR * scale {
            bottom = bottom.max(v);
        }
    }
    (top.is_finite() && bottom.is_finite()).then_some(bottom - top)
}

/// The longest near-vertical line whose middle is near the post.
fn longest_post_line(lines: &[Line], at: [f32; 2], scale: f32, post_u: f32) -> f32 {
    lines
        .iter()
        .filter(|l| (l.orientation_deg - 90.0).abs() < SQUARE_DEG)
        .filter(|l| {
            let mid = [(l.from[0] + l.to[0]) / 2.0, (l.from[1] + l.to[1]) / 2.0];
            (mid[0] - post_u).abs() < NEAR_POST * scale && (mid[1] - at[1]).abs() < 0.35 * scale
        })
        .map(|l| l.length)
        .fold(0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hough::tests::line;

    #[test]
    fn without_the_bars_the_posts_heights_are_the_longest_lines_near_them() {
        // Left post 60 px tall, right post 66 px (the right is nearer), both broken by noise into
        // a long and a short piece; a vertical line elsewhere is ignored.
        let lines = [
            line([100.0, 170.0], [100.0, 230.0]),
            line([100.0, 150.0], [100.0, 160.0]),
            line([220.0, 167.0], [220.0, 233.0]),
            line([160.0, 100.0], [160.0, 300.0]),
            line([215.0, 200.0], [240.0, 200.0]),
        ];
        assert_eq!(post_heights(&lines, [160.0, 200.0], 60.0), [60.0, 66.0]);
        assert_eq!(post_heights(&lines, [400.0, 200.0], 60.0), [0.0, 0.0]);
    }

    #[test]
    fn the_bars_edges_give_the_posts_whole_heights_where_the_posts_lines_are_broken() {
        // A frame turned so that its right post is nearer: its bars slant, 60 px apart at the
        // left post (u = 100) and 66 at the right (u = 220). Each bar has an outer and an inner
        // edge (8 px inside); the bars' outer edges are broken in the middle; the posts show only
        // their stretch between the bars' inner edges.
        let top = |u: f32| 170.0 - 3.0 * (u - 100.0) / 120.0;
        let bottom = |u: f32| 230.0 + 3.0 * (u - 100.0) / 120.0;
        let lines = [
            line([100.0, top(100.0)], [150.0, top(150.0)]),
            line([170.0, top(170.0)], [220.0, top(220.0)]),
            line([104.0, top(104.0) + 8.0], [216.0, top(216.0) + 8.0]),
            line([100.0, bottom(100.0)], [220.0, bottom(220.0)]),
            line([104.0, bottom(104.0) - 8.0], [216.0, bottom(216.0) - 8.0]),
            line([100.0, 178.0], [100.0, 222.0]),
            line([220.0, 175.0], [220.0, 225.0]),
        ];
        let [left, right] = post_heights(&lines, [160.0, 200.0], 60.0);
        assert!((left - 60.0).abs() < 1e-3 && (right - 66.0).abs() < 1e-3, "{left} {right}");
    }
}
