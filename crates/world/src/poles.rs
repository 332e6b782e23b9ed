//! Coded poles at seeded random places (004 §5, the AAAI-92 competition): a world's `[poles]`
//! table says how many, where they may stand and how they are marked; `World::place_poles`
//! puts them down for a seed, as eight-sided pillars with three bright rings of "retro-reflective
//! tape": the top and bottom rings at fixed heights (their spacing gives the range), the middle
//! ring's height the pole's code.

use serde::Deserialize;

use harvey_geometry::Rng;

use crate::{Region, Wall, World};

/// The `[poles]` table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoleField {
    pub count: u32,
    /// Poles stand inside this rectangle (`[x0, y0], [x1, y1]`), at least `clearance_m` from
    /// every wall, every other pole and the start.
    pub area_m: [[f64; 2]; 2],
    pub clearance_m: f64,
    pub side_m: f64,
    pub height_m: f64,
    pub reflectance: f64,
    /// The rings: their height (m) and reflectance; the top and bottom rings' centres; the middle
    /// ring's centre for code `k` is `code_base_m + k * code_step_m`.
    pub ring_m: f64,
    pub ring_reflectance: f64,
    pub top_m: f64,
    pub bottom_m: f64,
    pub code_base_m: f64,
    pub code_step_m: f64,
    /// A pole counts as visited once the robot's centre comes this close to the pole's centre.
    pub visit_m: f64,
}

/// A round pillar standing in the world: where its centre is and its radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pillar {
    pub at: [f64; 2],
    pub radius_m: f64,
}

/// One pole put down: its code and where its centre is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pole {
    pub code: u32,
    pub at: [f64; 2],
}

impl PoleField {
    /// Where the middle ring of code `k` is centred.
    pub fn code_height_m(&self, k: u32) -> f64 {
        self.code_base_m + f64::from(k) * self.code_step_m
    }

    /// The code whose middle ring is nearest `height_m`, if within half a step.
    pub fn code_at(&self, height_m: f64) -> Option<u32> {
        let k = ((height_m - self.code_base_m) / self.code_step_m).round();
        (k >= 0.0
            && k < f64::from(self.count)
            && (height_m - self.code_height_m(k as u32)).abs() < self.code_step_m / 2.0)
            .then_some(k as u32)
    }

    /// When `path` (time in s, position) first came within `visit_m` of each of `poles`, in
    /// their order; `None` for a pole never visited.
    pub fn first_visits(&self, poles: &[Pole], path: &[(f64, [f64; 2])]) -> Vec<Option<f64>> {
        poles
            .iter()
            .map(|p| {
                path.iter()
                    .find(|(_, q)| (q[0] - p.at[0]).hypot(q[1] - p.at[1]) < self.visit_m)
                    .map(|(t, _)| *t)
            })
            .collect()
    }
}

/// Why the `[poles]` could not be put down.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoleError {
    /// 10 000 random places for pole `code` were all too near a wall, a pole or the start.
    #[error("no room for pole {code} in {area_m:?} with {clearance_m} m clearance")]
    NoRoom { code: u32, area_m: [[f64; 2]; 2], clearance_m: f64 },
}

/// Distance from `p` to the segment `a`-`b`.
fn to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy).max(1e-12)).clamp(0.0, 1.0);
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

impl World {
    /// The round pillars put down ([`World::place_poles`]), for the sonar: a real pole returns
    /// an echo from the point of it nearest the sensor, which the eight faces it is drawn with
    /// do not when the beam meets them obliquely.
    pub fn pillars(&self) -> &[Pillar] {
        &self.pillars
    }

    /// Puts the `[poles]` down for `seed` (none without the table) and returns them, code order.
    /// Call before adding movers: the poles are static walls.
    pub fn place_poles(&mut self, seed: u64) -> Result<Vec<Pole>, PoleError> {
        let Some(f) = self.poles.clone() else { return Ok(Vec::new()) };
        let mut rng = Rng::new(seed ^ 0x5151_7e1e_c0de_0001);
        let mut placed: Vec<Pole> = Vec::new();
        let start = [self.start.x_m, self.start.y_m];
        for code in 0..f.count {
            let mut tries = 0;
            let at = loop {
                tries += 1;
                if tries > 10_000 {
                    return Err(PoleError::NoRoom { code, area_m: f.area_m, clearance_m: f.clearance_m });
                }
                let [[x0, y0], [x1, y1]] = f.area_m;
                let p = [x0 + (x1 - x0) * rng.unit(), y0 + (y1 - y0) * rng.unit()];
                let clear = self.walls.iter().all(|w| to_segment(p, w.from, w.to) >= f.clearance_m)
                    && placed.iter().all(|q| (q.at[0] - p[0]).hypot(q.at[1] - p[1]) >= f.clearance_m)
                    && (start[0] - p[0]).hypot(start[1] - p[1]) >= f.clearance_m;
                if clear {
                    break p;
                }
            };
            placed.push(Pole { code, at });
        }
        // Eight faces round, `side_m` across the flats: a round pole, to the sonar too (a square
        // one seen corner-on sends every echo away, 001 §3.4).
        let across = f.side_m / 2.0 / (std::f64::consts::PI / 8.0).cos();
        let face = 2.0 * across * (std::f64::consts::PI / 8.0).sin();
        for p in &placed {
            self.pillars.push(Pillar { at: p.at, radius_m: f.side_m / 2.0 });
            let corners: Vec<[f64; 2]> = (0..8)
                .map(|k| {
                    let a = (f64::from(k) + 0.5) * std::f64::consts::FRAC_PI_4;
                    [p.at[0] + across * a.cos(), p.at[1] + across * a.sin()]
                })
                .collect();
            let ring = |centre: f64| Region {
                along_m: [0.0, face],
                height_m: [centre - f.ring_m / 2.0, centre + f.ring_m / 2.0],
                reflectance: f.ring_reflectance,
                colour: [1.0, 1.0, 1.0],
            };
            let rings = [f.top_m, f.bottom_m, f.code_height_m(p.code)].map(ring);
            for k in 0..8 {
                self.walls.push(Wall {
                    from: corners[k],
                    to: corners[(k + 1) % 8],
                    height_m: f.height_m,
                    reflectance: f.reflectance,
                    colour: [1.0, 1.0, 1.0],
                    regions: rings.to_vec(),
                });
            }
        }
        Ok(placed)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn poles_go_down_clear_of_walls_and_each_other_the_same_way_for_a_seed() {
        let text = include_str!("../../../worlds/arena.toml");
        let place = |seed| {
            let mut w = crate::load_str(text, "arena.toml").expect("loads");
            let walls = w.walls.len();
            let poles = w.place_poles(seed).expect("room");
            assert_eq!(w.walls.len(), walls + 8 * poles.len());
            poles
        };
        let (a, b, c) = (place(1), place(1), place(2));
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_eq!(a.len(), 10);
        let w = crate::load_str(text, "arena.toml").expect("loads");
        let f = w.poles.clone().expect("a [poles] table");
        for p in &a {
            assert!(
                a.iter()
                    .filter(|q| q.code != p.code)
                    .all(|q| (q.at[0] - p.at[0]).hypot(q.at[1] - p.at[1]) >= f.clearance_m)
            );
            assert!(w.walls.iter().all(|wall| super::to_segment(p.at, wall.from, wall.to) >= f.clearance_m));
        }
        for k in 0..10 {
            assert_eq!(f.code_at(f.code_height_m(k) + 0.3 * f.code_step_m), Some(k));
        }
        assert_eq!(f.code_at(f.code_height_m(9) + f.code_step_m), None);
    }

    #[test]
    fn a_field_too_small_for_its_poles_says_so() {
        let mut w = crate::load_str(include_str!("../../../worlds/arena.toml"), "arena.toml").expect("loads");
        // The arena is 14 m by 12 m: nothing in it is seen further than its diagonal.
        assert!((w.diagonal_m() - 14f64.hypot(12.0)).abs() < 1e-9, "{}", w.diagonal_m());
        let f = w.poles.as_mut().expect("a [poles] table");
        let [[x0, y0], _] = f.area_m;
        f.area_m[1] = [x0 + 0.01, y0 + 0.01];
        let e = w.place_poles(1).expect_err("no room for two poles in a square centimetre");
        assert!(matches!(e, super::PoleError::NoRoom { .. }), "{e:?}");
        let text = e.to_string();
        assert!(text.starts_with("no room for pole ") && text.ends_with(" m clearance"), "{text}");
    }

    #[test]
    fn a_pole_is_visited_when_the_path_first_comes_within_visit_m_of_it() {
        let w = crate::load_str(include_str!("../../../worlds/arena.toml"), "arena.toml").expect("loads");
        let f = w.poles.clone().expect("a [poles] table");
        let poles = [super::Pole { code: 0, at: [5.0, 5.0] }, super::Pole { code: 1, at: [9.0, 5.0] }];
        // Along y = 5 + 0.8 m (inside 0.9 m of both centres' x) from x = 0 to 6, at 1 m/s.
        let path: Vec<(f64, [f64; 2])> =
            (0..=60).map(|k| (f64::from(k) / 10.0, [f64::from(k) / 10.0, 5.8])).collect();
        let visits = f.first_visits(&poles, &path);
        let first = visits[0].expect("passes the first pole");
        // (x - 5)^2 + 0.8^2 < 0.9^2 first at x = 4.6 (0.412 m along x).
        assert!((first - 4.6).abs() < 1e-9, "{first}");
        assert_eq!(visits[1], None, "never near the second");
    }
}
