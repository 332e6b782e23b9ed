//! Property tests of the map's geometry, over seeded random cases: hulls are convex and hold
//! their points; slicing never grows a polygon; a sighting consistent with the truth never
//! removes the true pose, and never grows the map.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_ums::geometry::{self, Pt};
use harvey_ums::map::{Growth, Map};
use harvey_ums::reduction::{Known, Observation, apply};

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f()
    }
}

fn convex(poly: &[Pt]) -> bool {
    let n = poly.len();
    n < 3
        || (0..n).all(|i| {
            let (a, b, c) = (poly[i], poly[(i + 1) % n], poly[(i + 2) % n]);
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) >= -1e-9
        })
}

fn tile() -> harvey_world::Terrain {
    let w = harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("hallway");
    w.terrain["tile"].clone()
}

#[test]
fn hulls_are_convex_and_hold_every_point() {
    let mut r = Rng(1);
    for _ in 0..500 {
        let pts: Vec<Pt> =
            (0..(3 + (r.f() * 40.0) as usize)).map(|_| [r.range(-5.0, 5.0), r.range(-5.0, 5.0)]).collect();
        let h = geometry::hull(&pts);
        assert!(convex(&h), "{h:?}");
        assert!(pts.iter().all(|p| geometry::contains(&h, *p, 1e-9)));
        let small = geometry::limit_vertices(h.clone(), 5);
        assert!(
            small.len() <= 5 && convex(&small) && pts.iter().all(|p| geometry::contains(&small, *p, 1e-7))
        );
    }
}

#[test]
fn slicing_never_grows_a_polygon() {
    let mut r = Rng(2);
    for _ in 0..1000 {
        let pts: Vec<Pt> = (0..8).map(|_| [r.range(-5.0, 5.0), r.range(-5.0, 5.0)]).collect();
        let h = geometry::hull(&pts);
        let a = r.range(0.0, std::f64::consts::TAU);
        let cut = geometry::clip(&h, [a.cos(), a.sin()], r.range(-3.0, 3.0));
        assert!(geometry::area(&cut) <= geometry::area(&h) + 1e-9);
        assert!(convex(&cut) && cut.iter().all(|p| geometry::contains(&h, *p, 1e-9)));
    }
}

#[test]
fn consistent_sightings_keep_the_truth_and_never_grow_the_map() {
    let terrain = tile();
    let growth = Growth { terrain: &terrain, sigmas: 3.0 };
    let mut r = Rng(3);
    let mut applied = 0;
    for case in 0..600 {
        let mut map = Map::exact(0.0, 0.0, r.range(-3.0, 3.0));
        for _ in 0..3 {
            growth.turn(&mut map, r.range(-1.5, 1.5));
            growth.run(&mut map, r.range(0.5, 4.0), true);
        }
        // A truth inside the map: a random point of the polygon and a heading in the wedge.
        let w: Vec<f64> = map.polygon.iter().map(|_| r.f()).collect();
        let sum: f64 = w.iter().sum();
        let p = map
            .polygon
            .iter()
            .zip(&w)
            .fold([0.0, 0.0], |a, (v, k)| [a[0] + v[0] * k / sum, a[1] + v[1] * k / sum]);
        let [lo, hi] = map.wedge();
        let heading = r.range(lo, hi);
        assert!(map.contains(p, heading, 1e-9));
        // A landmark somewhere ahead-ish, and what a sensor with these errors would report.
        let bearing = r.range(-0.5, 0.5);
        let dist = r.range(2.0, 12.0);
        let l = [p[0] + dist * (heading + bearing).cos(), p[1] + dist * (heading + bearing).sin()];
        let (sd, range_sd) = (0.01, 0.05);
        let point = Known { at: l, to: None, position_sd_m: 0.0 };
        let (known, obs) = match case % 3 {
            0 => (point, Observation::Bearing { bearing_rad: bearing + r.range(-sd, sd), sd_rad: sd }),
            1 => (
                point,
                Observation::BearingRange {
                    bearing_rad: bearing + r.range(-sd, sd),
                    sd_rad: sd,
                    range_m: dist + r.range(-range_sd, range_sd),
                    range_sd_m: range_sd,
                },
            ),
            _ => {
                // A ground line through l in a random direction g: the robot's offset from it
                // (left positive) and its heading relative to it.
                let g = r.range(-3.0, 3.0);
                let u = [g.cos(), g.sin()];
                let offset = -(p[0] - l[0]) * u[1] + (p[1] - l[1]) * u[0];
                let rel = harvey_ums::map::wrap(heading - g);
                (
                    Known { at: l, to: Some([l[0] + 5.0 * u[0], l[1] + 5.0 * u[1]]), position_sd_m: 0.0 },
                    Observation::GroundLine {
                        heading_rad: rel + r.range(-sd, sd),
                        heading_sd_rad: sd,
                        offset_m: offset + r.range(-range_sd, range_sd),
                        offset_sd_m: range_sd,
                    },
                )
            }
        };
        let after = apply(&map, &known, &obs, 3.0).unwrap_or_else(|e| panic!("case {case}: {e}: {obs:?}"));
        assert!(after.contains(p, heading, 1e-7), "case {case}: the truth was sliced away by {obs:?}");
        assert!(after.area_m2() <= map.area_m2() + 1e-9, "case {case}: area grew");
        assert!(after.cw_rad + after.ccw_rad <= map.cw_rad + map.ccw_rad + 1e-12, "case {case}: wedge grew");
        applied += 1;
    }
    assert_eq!(applied, 600);
}

#[test]
fn inconsistent_sightings_are_rejected_and_the_map_kept() {
    let terrain = tile();
    let growth = Growth { terrain: &terrain, sigmas: 3.0 };
    let mut map = Map::exact(0.0, 0.0, 0.0);
    growth.run(&mut map, 3.0, true);
    let behind = Known { at: [-20.0, 0.0], to: None, position_sd_m: 0.0 };
    // Seen straight ahead, but the landmark is far behind every possible pose.
    let e = apply(&map, &behind, &Observation::Bearing { bearing_rad: 0.0, sd_rad: 0.001 }, 3.0);
    assert!(e.is_err(), "{e:?}");
    let nan = apply(&map, &behind, &Observation::Bearing { bearing_rad: f64::NAN, sd_rad: 0.01 }, 3.0);
    assert_eq!(nan, Err(harvey_ums::reduction::Rejection::NotFinite));
    let no_line = apply(
        &map,
        &behind,
        &Observation::GroundLine { heading_rad: 0.0, heading_sd_rad: 0.01, offset_m: 0.0, offset_sd_m: 0.1 },
        3.0,
    );
    assert_eq!(no_line, Err(harvey_ums::reduction::Rejection::NoLine));
}
