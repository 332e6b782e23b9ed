//! Things that move through the world on a timetable (a cart down the hall, a passer-by, a
//! door's occluder): a footprint polygon with a height and a reflectance, driven along
//! time-stamped waypoints. A mission's launch file lists them as `[[mover]]` tables; the
//! simulator's sonar and the camera place them at each tick's simulated time, as walls.

use serde::Deserialize;

use crate::bounds::{FRACTION, POSITION};
use crate::{Inconsistency, Wall, World, WorldError};
use harvey_config::range::{OutOfRange, Range, check, check_all, check_len};
use harvey_config::spans::{KeyPath, line_of};

/// One moving thing.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mover {
    pub name: String,
    /// Footprint corners around its reference point (m), in order.
    pub outline: Vec<[f64; 2]>,
    pub height_m: f64,
    pub reflectance: f64,
    /// `[t_s, x_m, y_m]`: where the reference point is at simulated time `t_s`; in between it
    /// moves in a straight line, before the first and after the last it stands still.
    pub path: Vec<[f64; 3]>,
    /// Horizontal bands painted round it (a traffic cone's reflective collar, a box's tape):
    /// `[from_m, to_m, reflectance]`, heights above the floor.
    #[serde(default)]
    pub bands: Vec<[f64; 3]>,
}

impl Mover {
    /// Where its reference point is at `t_s`.
    pub fn at(&self, t_s: f64) -> [f64; 2] {
        let p = &self.path;
        let k = p.iter().position(|w| w[0] > t_s).unwrap_or(p.len());
        match k {
            0 => [p[0][1], p[0][2]],
            k if k == p.len() => [p[k - 1][1], p[k - 1][2]],
            k => {
                let (a, b) = (p[k - 1], p[k]);
                let f = (t_s - a[0]) / (b[0] - a[0]);
                [a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])]
            }
        }
    }
}

/// The launch file as far as movers go: other tables are other services' business.
#[derive(Deserialize)]
struct File {
    #[serde(default, rename = "mover")]
    movers: Vec<Mover>,
}

/// How many movers a launch file may hold, and corners and waypoints each: the simulator and
/// the camera turn every corner into a wall each tick and search the path each tick.
const MAX_MOVERS: usize = 1_000;
const MAX_CORNERS: usize = 1_000;
const MAX_WAYPOINTS: usize = 10_000;
/// Path times: simulated seconds, up to some four months either way.
const TIME: Range = Range::within(1e7, "s");

/// The `[[mover]]` tables of a launch file (other tables are other services' business).
pub fn parse_movers(text: &str, file: &str) -> Result<Vec<Mover>, WorldError> {
    let bad = |why: Inconsistency| WorldError::Inconsistent { file: file.to_owned(), why };
    let parsed: File = serde_path_to_error::deserialize(toml::Deserializer::new(text)).map_err(|e| {
        let field = e.path().to_string();
        let inner = e.into_inner();
        let line = inner.span().map_or(0, |s| line_of(text, s.start));
        WorldError::Parse { file: file.to_owned(), line, field, detail: inner.message().to_owned() }
    })?;
    let movers = KeyPath::default().key("mover");
    check_len(&movers, parsed.movers.len(), MAX_MOVERS, "movers")
        .map_err(|why| WorldError::out_of_range(text, file, why))?;
    for (i, m) in parsed.movers.iter().enumerate() {
        check_mover(&movers.index(i), m).map_err(|mut why| {
            why.detail = format!("mover {}: {}", m.name, why.detail);
            WorldError::out_of_range(text, file, why)
        })?;
        let finite = m.outline.iter().flatten().chain(m.path.iter().flatten()).all(|v| v.is_finite());
        if m.outline.len() < 3 || m.path.is_empty() || !finite {
            return Err(bad(Inconsistency::MoverShape { mover: m.name.clone() }));
        }
        if m.path.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return Err(bad(Inconsistency::MoverTimes { mover: m.name.clone() }));
        }
        let band_fits =
            |b: &[f64; 3]| 0.0 <= b[0] && b[0] < b[1] && b[1] <= m.height_m && (0.0..=1.0).contains(&b[2]);
        if m.height_m.is_nan()
            || m.height_m <= 0.0
            || !(0.0..=1.0).contains(&m.reflectance)
            || !m.bands.iter().all(band_fits)
        {
            return Err(bad(Inconsistency::MoverLook { mover: m.name.clone() }));
        }
    }
    Ok(parsed.movers)
}

/// Every number of the mover at `k` in its range, its lists within their caps.
fn check_mover(k: &KeyPath, m: &Mover) -> Result<(), OutOfRange> {
    check_len(&k.key("outline"), m.outline.len(), MAX_CORNERS, "corners")?;
    for (i, c) in m.outline.iter().enumerate() {
        check_all(&k.key("outline").index(i), c, &POSITION)?;
    }
    check(&k.key("height_m"), m.height_m, &Range::above(0.0, 100.0, "m"))?;
    check(&k.key("reflectance"), m.reflectance, &FRACTION)?;
    check_len(&k.key("bands"), m.bands.len(), MAX_CORNERS, "bands")?;
    check_len(&k.key("path"), m.path.len(), MAX_WAYPOINTS, "waypoints")?;
    for (i, [t, x, y]) in m.path.iter().enumerate() {
        let p = k.key("path").index(i);
        check(&p.index(0), *t, &TIME)?;
        check(&p.index(1), *x, &POSITION)?;
        check(&p.index(2), *y, &POSITION)?;
    }
    Ok(())
}

/// [`parse_movers`] on a file.
pub fn load_movers(path: &std::path::Path) -> Result<Vec<Mover>, WorldError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| WorldError::Io { file: file.clone(), detail: e.to_string() })?;
    parse_movers(&text, &file)
}

impl World {
    /// Adds moving things; their walls follow the static ones and [`World::set_time`] places them.
    pub fn add_movers(&mut self, movers: Vec<Mover>) {
        if self.movers.is_empty() {
            self.static_walls = self.walls.len();
        }
        self.movers.extend(movers);
        self.set_time(0.0);
    }

    /// Puts every mover where it is at simulated time `t_s` (its outline's edges become walls).
    pub fn set_time(&mut self, t_s: f64) {
        if self.movers.is_empty() {
            return;
        }
        self.walls.truncate(self.static_walls);
        for m in &self.movers {
            let [x, y] = m.at(t_s);
            let n = m.outline.len();
            for k in 0..n {
                let (a, b) = (m.outline[k], m.outline[(k + 1) % n]);
                let length = (b[0] - a[0]).hypot(b[1] - a[1]);
                let regions = m
                    .bands
                    .iter()
                    .map(|&[lo, hi, reflectance]| crate::Region {
                        along_m: [0.0, length],
                        height_m: [lo, hi],
                        reflectance,
                        colour: [1.0, 1.0, 1.0],
                    })
                    .collect();
                self.walls.push(Wall {
                    from: [x + a[0], y + a[1]],
                    to: [x + b[0], y + b[1]],
                    height_m: m.height_m,
                    reflectance: m.reflectance,
                    colour: [1.0, 1.0, 1.0],
                    regions,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CART: &str = "[launch]\nname = \"x\"\n[[mover]]\nname = \"cart\"\noutline = [[-0.3, -0.25], [0.3, -0.25], [0.3, 0.25], [-0.3, 0.25]]\nheight_m = 1.0\nreflectance = 0.3\npath = [[2.0, 10.0, 0.0], [12.0, 5.0, 0.0]]\n";

    #[test]
    fn a_mover_follows_its_timetable_and_becomes_walls() {
        let movers = parse_movers(CART, "m.toml").expect("parses");
        let cart = &movers[0];
        assert_eq!(cart.at(0.0), [10.0, 0.0]);
        assert_eq!(cart.at(7.0), [7.5, 0.0]);
        assert_eq!(cart.at(99.0), [5.0, 0.0]);
        let mut w = crate::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("world");
        let walls = w.walls.len();
        let ahead = |w: &World| w.cast_ray([0.0, 0.0], [1.0, 0.0], 30.0).map(|h| h.distance_m);
        let without = ahead(&w).expect("the end wall");
        w.add_movers(movers);
        assert_eq!(w.walls.len(), walls + 4);
        assert!((ahead(&w).expect("the cart") - 9.7).abs() < 1e-9);
        w.set_time(12.0);
        assert!((ahead(&w).expect("the cart") - 4.7).abs() < 1e-9);
        assert_eq!(w.walls.len(), walls + 4, "placing again replaces the mover's walls");
        assert!(without > 15.0);
    }

    #[test]
    fn bad_movers_are_named() {
        let e =
            parse_movers(&CART.replace("[12.0, 5.0", "[1.0, 5.0"), "m.toml").expect_err("times").to_string();
        assert!(e.contains("m.toml") && e.contains("mover cart: path times must increase"), "{e}");
        let e = parse_movers(&CART.replace("height_m = 1.0", "height_m = -1.0"), "m.toml")
            .expect_err("h")
            .to_string();
        assert!(e.contains("mover cart"), "{e}");
        assert_eq!(parse_movers("[launch]\nname = \"x\"\n", "m.toml").expect("none").len(), 0);
    }
}
