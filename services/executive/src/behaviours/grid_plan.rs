//! The path round the obstacles stereo has seen (003: "obstacles detected from the 3-D points
//! and a path planned round them"): the points on a grid of the room, each making the cells
//! within a clearance of it dear (the margin) or dearer (the robot's own reach), and the
//! cheapest 8-connected path from the robot to the goal by A*, walked a step's length along. A
//! blocked cell is dear, not impassable, so a robot that finds itself in a margin plans its way
//! out, and the sonar's reflexes guard what stereo missed.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// What a step into a cell costs, by how it is blocked (free, in a margin, within reach).
const COST: [u64; 3] = [1, 10, 100];

/// The last stop's path is kept while a fresh one would not cost a fifth less (a stated value):
/// without it, the path's first cells flipped from one side of an obstacle to the other between
/// stops and the robot turned to and fro in turn-only steps.
const KEEP_ROUTE: f64 = 1.25;

/// The grid: the room's extent, the cell side, how each cell is blocked (0 free, 1 a margin, 2
/// within reach).
#[derive(Debug, Clone)]
pub struct Grid {
    origin: [f64; 2],
    cell_m: f64,
    size: [usize; 2],
    blocked: Vec<u8>,
}

impl Grid {
    /// A grid over `min..max` (m) of `cell_m` cells, nothing blocked.
    pub fn new(min: [f64; 2], max: [f64; 2], cell_m: f64) -> Self {
        let size = [0, 1].map(|k| (((max[k] - min[k]) / cell_m).ceil() as usize).clamp(1, 2000));
        Self { origin: min, cell_m, size, blocked: vec![0; size[0] * size[1]] }
    }

    fn cell(&self, p: [f64; 2]) -> Option<[usize; 2]> {
        let c = [0, 1].map(|k| ((p[k] - self.origin[k]) / self.cell_m).floor());
        let inside = (0..2).all(|k| c[k] >= 0.0 && (c[k] as usize) < self.size[k]);
        inside.then(|| c.map(|v| v as usize))
    }

    fn centre(&self, c: [usize; 2]) -> [f64; 2] {
        [0, 1].map(|k| self.origin[k] + (c[k] as f64 + 0.5) * self.cell_m)
    }

    /// Blocks every cell whose centre is within `clearance_m` of `p` at `level` (1 a margin, 2
    /// within reach), or more if it already is.
    pub fn block(&mut self, p: [f64; 2], clearance_m: f64, level: u8) {
        let reach = (clearance_m / self.cell_m).ceil() as i64 + 1;
        let Some(c) = self.cell(p) else { return };
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let (x, y) = (c[0] as i64 + dx, c[1] as i64 + dy);
                if x < 0 || y < 0 || x as usize >= self.size[0] || y as usize >= self.size[1] {
                    continue;
                }
                let q = [x as usize, y as usize];
                let m = self.centre(q);
                let cell = &mut self.blocked[q[1] * self.size[0] + q[0]];
                if (m[0] - p[0]).hypot(m[1] - p[1]) <= clearance_m {
                    *cell = (*cell).max(level.min(2));
                }
            }
        }
    }

    /// How `p`'s cell is blocked (2 outside the grid).
    pub fn blocked(&self, p: [f64; 2]) -> u8 {
        self.cell(p).map_or(2, |c| self.blocked[c[1] * self.size[0] + c[0]])
    }

    /// The cheapest path (cell centres, the goal last) from `from` to `to`. `None` if either is
    /// outside the grid.
    pub fn path(&self, from: [f64; 2], to: [f64; 2]) -> Option<Vec<[f64; 2]>> {
        let (start, goal) = (self.cell(from)?, self.cell(to)?);
        let w = self.size[0];
        let index = |c: [usize; 2]| c[1] * w + c[0];
        // Costs in thousandths of a cell, so the heap orders integers.
        let h = |c: [usize; 2]| {
            let (dx, dy) = (c[0].abs_diff(goal[0]) as u64, c[1].abs_diff(goal[1]) as u64);
            1000 * dx.max(dy) + 414 * dx.min(dy)
        };
        let mut cost = vec![u64::MAX; self.blocked.len()];
        let mut came = vec![usize::MAX; self.blocked.len()];
        let mut open = BinaryHeap::new();
        cost[index(start)] = 0;
        open.push(Reverse((h(start), index(start))));
        while let Some(Reverse((_, i))) = open.pop() {
            let c = [i % w, i / w];
            if c == goal {
                let mut path = vec![self.centre(c)];
                let mut k = i;
                while came[k] != usize::MAX {
                    k = came[k];
                    path.push(self.centre([k % w, k / w]));
                }
                path.pop();
                path.reverse();
                if let Some(last) = path.last_mut() {
                    *last = to;
                }
                return Some(path);
            }
            for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1)] {
                let (x, y) = (c[0] as i64 + dx, c[1] as i64 + dy);
                if x < 0 || y < 0 || x as usize >= w || y as usize >= self.size[1] {
                    continue;
                }
                let j = y as usize * w + x as usize;
                let step = if dx != 0 && dy != 0 { 1414 } else { 1000 } * COST[usize::from(self.blocked[j])];
                let next = cost[i] + step;
                if next < cost[j] {
                    cost[j] = next;
                    came[j] = i;
                    open.push(Reverse((next + h([x as usize, y as usize]), j)));
                }
            }
        }
        None
    }
}

impl Grid {
    /// What walking from `from` through `path` costs, in the search's units (a free cell's
    /// length 1, a margin's 10, a reach's 100), sampled every half cell.
    pub fn cost(&self, from: [f64; 2], path: &[[f64; 2]]) -> f64 {
        let mut at = from;
        let mut sum = 0.0;
        for p in path {
            let d = (p[0] - at[0]).hypot(p[1] - at[1]);
            let n = (2.0 * d / self.cell_m).ceil().max(1.0) as usize;
            for k in 1..=n {
                let t = k as f64 / n as f64;
                let q = [at[0] + t * (p[0] - at[0]), at[1] + t * (p[1] - at[1])];
                sum += d / n as f64 / self.cell_m * COST[usize::from(self.blocked(q))] as f64;
            }
            at = *p;
        }
        sum
    }
}

/// The rest of the last stop's `route` (from its point nearest `here` on) while walking it costs
/// at most `KEEP_ROUTE` times the `fresh` path; else the fresh path.
pub fn kept_or_fresh(
    grid: &Grid,
    here: [f64; 2],
    mut route: Vec<[f64; 2]>,
    fresh: Vec<[f64; 2]>,
) -> Vec<[f64; 2]> {
    let nearest = (0..route.len()).min_by(|&a, &b| {
        let d = |p: [f64; 2]| (p[0] - here[0]).hypot(p[1] - here[1]);
        d(route[a]).total_cmp(&d(route[b]))
    });
    let kept = nearest.map(|i| route.split_off(i)).unwrap_or_default();
    let keep = !kept.is_empty() && grid.cost(here, &kept) <= KEEP_ROUTE * grid.cost(here, &fresh);
    if keep { kept } else { fresh }
}

/// The point `step_m` along `path` from `from` (the path's end if it is shorter).
pub fn along(from: [f64; 2], path: &[[f64; 2]], step_m: f64) -> [f64; 2] {
    let mut left = step_m;
    let mut at = from;
    for p in path {
        let d = (p[0] - at[0]).hypot(p[1] - at[1]);
        if d >= left {
            let t = left / d;
            return [at[0] + t * (p[0] - at[0]), at[1] + t * (p[1] - at[1])];
        }
        left -= d;
        at = *p;
    }
    at
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_path_goes_round_a_wall_of_points_and_a_step_is_walked_along_it() {
        let mut g = Grid::new([0.0, 0.0], [8.0, 6.0], 0.1);
        // A box's face across the straight line from (1, 3) to (7, 3), a margin and a reach.
        for k in 0..=6 {
            g.block([3.0, 2.7 + 0.1 * f64::from(k)], 0.6, 1);
            g.block([3.0, 2.7 + 0.1 * f64::from(k)], 0.35, 2);
        }
        assert_eq!(
            [g.blocked([3.0, 3.0]), g.blocked([3.0, 3.5]), g.blocked([3.0, 3.7]), g.blocked([3.0, 4.0])],
            [2, 2, 1, 0]
        );
        let path = g.path([1.0, 3.0], [7.0, 3.0]).expect("a way round");
        assert_eq!(path.last(), Some(&[7.0, 3.0]));
        assert!(path.iter().all(|p| g.blocked(*p) == 0), "round the margin when there is room");
        let widest = path.iter().map(|p| (p[1] - 3.0).abs()).fold(0.0, f64::max);
        assert!(widest > 0.85, "round the face's end, {widest}");
        let step = along([1.0, 3.0], &path, 0.4); // 0.4 m along cell centres: about 0.4 m on
        assert!(((step[0] - 1.0).hypot(step[1] - 3.0) - 0.4).abs() < 0.01, "{step:?}");
        assert_eq!(along([1.0, 3.0], &path, 100.0), [7.0, 3.0], "a short path ends at the goal");
        // A robot inside the margin plans its way out of it, the shortest way.
        let out = g.path([2.6, 3.0], [1.0, 3.0]).expect("out");
        assert!(out.iter().all(|p| g.blocked(*p) < 2), "{out:?}");
        // Walled in all round: the way out crosses the wall where it is thinnest, never outside.
        let mut pen = Grid::new([0.0, 0.0], [4.0, 4.0], 0.1);
        for k in 0..40 {
            let a = f64::from(k) * std::f64::consts::TAU / 40.0;
            pen.block([2.0 + a.cos(), 2.0 + a.sin()], 0.1, 2);
        }
        assert!(pen.path([2.0, 2.0], [0.2, 0.2]).is_some(), "dear, not impassable");
        assert!(g.blocked([9.0, 3.0]) == 2 && g.path([9.0, 3.0], [1.0, 1.0]).is_none(), "outside");
        // A walk's cost: free cells one a cell, through the margin and the reach dearer.
        let free = g.cost([1.0, 1.0], &[[7.0, 1.0]]);
        assert!((free - 60.0).abs() < 1e-9, "{free}");
        let through = g.cost([1.0, 3.0], &[[7.0, 3.0]]);
        assert!(through > 60.0 + 9.0 * 2.0 && through > g.cost([1.0, 3.0], &path), "{through}");
    }
}
