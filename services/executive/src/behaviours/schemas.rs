//! Motor schemas (001 §3.1, 004 §2.1): each behaviour is a velocity vector computed from what is
//! perceived now; the active schemas' vectors are summed, and the sum is clipped to the top
//! speed. move-to-goal attracts, avoid-static-obstacle repels within a sphere of influence,
//! noise (seeded) wanders to escape local minima, avoid-past repels from places recently
//! visited, and probe pulls towards open space.

use harvey_geometry::Rng;

/// A planar vector (m/s, or unit-free for directions), world frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct V2 {
    pub x: f64,
    pub y: f64,
}

impl V2 {
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }

    pub fn norm(self) -> f64 {
        self.x.hypot(self.y)
    }

    pub fn scale(self, k: f64) -> Self {
        Self::new(self.x * k, self.y * k)
    }

    pub fn plus(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y)
    }

    pub fn minus(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y)
    }

    /// The dot product: this one's length along `o`, times `o`'s.
    pub fn dot(self, o: Self) -> f64 {
        self.x * o.x + self.y * o.y
    }

    /// The unit vector along this one (zero stays zero).
    pub fn unit(self) -> Self {
        let n = self.norm();
        if n > 0.0 { self.scale(1.0 / n) } else { self }
    }
}

/// move-to-goal: `gain` towards the goal.
pub fn move_to_goal(at: V2, goal: V2, gain: f64) -> V2 {
    goal.minus(at).unit().scale(gain)
}

/// avoid-static-obstacle: nothing beyond the sphere of influence `sphere_m` of the obstacle's
/// edge; inside, away from the obstacle, growing linearly to `gain` at its edge (`radius_m`),
/// and `contact_gain` (a large number) inside it.
pub fn avoid_obstacle(
    at: V2,
    obstacle: V2,
    radius_m: f64,
    sphere_m: f64,
    gain: f64,
    contact_gain: f64,
) -> V2 {
    let away = at.minus(obstacle);
    let d = away.norm();
    if d >= radius_m + sphere_m {
        return V2::default();
    }
    let magnitude = if d <= radius_m { contact_gain } else { gain * (radius_m + sphere_m - d) / sphere_m };
    away.unit().scale(magnitude)
}

/// noise: a random direction of size `gain`, held for `persistence` steps, from a seeded
/// generator (same seed, same wandering).
#[derive(Debug, Clone)]
pub struct Noise {
    rng: Rng,
    held: V2,
    left: u32,
    pub gain: f64,
    pub persistence: u32,
}

impl Noise {
    pub fn new(seed: u64, gain: f64, persistence: u32) -> Self {
        Self {
            rng: Rng::new(seed ^ 0x9e37_79b9_7f4a_7c15),
            held: V2::default(),
            left: 0,
            gain,
            persistence: persistence.max(1),
        }
    }

    pub fn vector(&mut self) -> V2 {
        if self.left == 0 {
            let a = self.rng.unit() * std::f64::consts::TAU;
            (self.held, self.left) = (V2::new(a.cos(), a.sin()).scale(self.gain), self.persistence);
        }
        self.left -= 1;
        self.held
    }
}

/// avoid-past: a coarse grid of recent visits, each fading by `decay` a step; the robot is
/// pushed down the gradient of visits round it.
#[derive(Debug, Clone)]
pub struct AvoidPast {
    cell_m: f64,
    origin: V2,
    side: usize,
    visits: Vec<f64>,
    pub gain: f64,
    pub decay: f64,
}

impl AvoidPast {
    /// A `side x side` grid of `cell_m` cells centred on `centre`.
    pub fn new(centre: V2, side: usize, cell_m: f64, gain: f64, decay: f64) -> Self {
        let half = side as f64 * cell_m / 2.0;
        Self {
            cell_m,
            origin: centre.minus(V2::new(half, half)),
            side,
            visits: vec![0.0; side * side],
            gain,
            decay,
        }
    }

    fn cell(&self, p: V2) -> Option<(usize, usize)> {
        let (i, j) = ((p.x - self.origin.x) / self.cell_m, (p.y - self.origin.y) / self.cell_m);
        (i >= 0.0 && j >= 0.0 && (i as usize) < self.side && (j as usize) < self.side)
            .then_some((i as usize, j as usize))
    }

    /// Records a visit at `at` (older visits fade).
    pub fn visit(&mut self, at: V2) {
        self.visits.iter_mut().for_each(|v| *v *= self.decay);
        if let Some((i, j)) = self.cell(at) {
            self.visits[j * self.side + i] += 1.0;
        }
    }

    /// Away from the visited neighbourhood: the sum over the 8 neighbouring cells of their
    /// visits, each pushing from its direction.
    pub fn vector(&self, at: V2) -> V2 {
        let Some((i, j)) = self.cell(at) else { return V2::default() };
        let mut v = V2::default();
        for (di, dj) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
            let (ni, nj) = (i as isize + di, j as isize + dj);
            if ni < 0 || nj < 0 || ni as usize >= self.side || nj as usize >= self.side {
                continue;
            }
            let w = self.visits[nj as usize * self.side + ni as usize];
            v = v.plus(V2::new(-di as f64, -dj as f64).unit().scale(w));
        }
        v.scale(self.gain)
    }
}

/// probe: towards the most open direction, from free ranges by bearing (radians, world frame),
/// scaled by how much more open it is than the mean.
pub fn probe(ranges: &[(f64, f64)], gain: f64) -> V2 {
    let Some(&(bearing, far)) = ranges.iter().max_by(|a, b| a.1.total_cmp(&b.1)) else {
        return V2::default();
    };
    let mean = ranges.iter().map(|r| r.1).sum::<f64>() / ranges.len() as f64;
    if far <= 0.0 {
        return V2::default();
    }
    V2::new(bearing.cos(), bearing.sin()).scale(gain * (far - mean) / far)
}

/// The schemas' sum, clipped to `max_speed`.
pub fn combine(vectors: &[V2], max_speed: f64) -> V2 {
    let sum = vectors.iter().fold(V2::default(), |a, v| a.plus(*v));
    if sum.norm() > max_speed { sum.unit().scale(max_speed) } else { sum }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_schema_points_where_it_should() {
        let at = V2::new(0.0, 0.0);
        let near = |a: V2, b: V2| (a.x - b.x).abs() < 1e-12 && (a.y - b.y).abs() < 1e-12;
        assert!(near(move_to_goal(at, V2::new(3.0, 4.0), 2.0), V2::new(1.2, 1.6)));
        // Obstacle 1 m ahead, radius 0.3, sphere 1.0: pushed back, half strength at 0.7 m from the edge.
        let push = avoid_obstacle(at, V2::new(1.0, 0.0), 0.3, 1.0, 1.0, 1e3);
        assert!((push.x + 0.3).abs() < 1e-12 && push.y == 0.0, "{push:?}");
        assert_eq!(avoid_obstacle(at, V2::new(2.0, 0.0), 0.3, 1.0, 1.0, 1e3), V2::default());
        assert_eq!(avoid_obstacle(at, V2::new(0.2, 0.0), 0.3, 1.0, 1.0, 1e3), V2::new(-1e3, 0.0));
        let open = probe(&[(0.0, 1.0), (std::f64::consts::FRAC_PI_2, 5.0), (std::f64::consts::PI, 1.0)], 1.0);
        assert!(open.y > 0.5 && open.x.abs() < 1e-9, "{open:?}");
        assert!(near(combine(&[V2::new(3.0, 0.0), V2::new(0.0, 4.0)], 1.0), V2::new(0.6, 0.8)));
    }

    #[test]
    fn noise_is_seeded_and_persistent() {
        let (mut a, mut b) = (Noise::new(7, 0.5, 3), Noise::new(7, 0.5, 3));
        let seq: Vec<V2> = (0..9).map(|_| a.vector()).collect();
        assert_eq!(seq, (0..9).map(|_| b.vector()).collect::<Vec<_>>());
        assert!(seq[0] == seq[2] && seq[2] != seq[3], "held for 3 steps");
        assert!(seq.iter().all(|v| (v.norm() - 0.5).abs() < 1e-12));
        assert_ne!(seq, (0..9).map(|_| Noise::new(8, 0.5, 3).vector()).collect::<Vec<_>>());
    }

    #[test]
    fn avoid_past_pushes_away_from_where_the_robot_has_been() {
        let mut past = AvoidPast::new(V2::default(), 20, 0.5, 1.0, 0.99);
        for k in 0..10 {
            past.visit(V2::new(-0.5 * f64::from(k) / 10.0 - 0.3, 0.1));
        }
        let v = past.vector(V2::new(0.1, 0.1));
        assert!(v.x > 0.0 && v.x.abs() > v.y.abs(), "{v:?}");
    }

    #[test]
    fn goal_obstacle_and_noise_together_reach_the_goal_round_the_obstacle() {
        // A point robot, 0.1 s steps: the obstacle sits right on the straight line to the goal.
        let (goal, obstacle) = (V2::new(6.0, 0.0), V2::new(3.0, 0.05));
        let mut noise = Noise::new(3, 0.1, 5);
        let mut at = V2::default();
        let mut closest = f64::MAX;
        for _ in 0..600 {
            let v = combine(
                &[
                    move_to_goal(at, goal, 1.0),
                    avoid_obstacle(at, obstacle, 0.4, 1.0, 1.5, 100.0),
                    noise.vector(),
                ],
                1.0,
            );
            at = at.plus(v.scale(0.1));
            closest = closest.min(at.minus(obstacle).norm());
            if at.minus(goal).norm() < 0.1 {
                break;
            }
        }
        assert!(at.minus(goal).norm() < 0.1, "stuck at {at:?}");
        assert!(closest > 0.4, "touched the obstacle: {closest}");
    }
}
