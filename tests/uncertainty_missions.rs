//! 002 Fig. 79 against Fig. 80 as missions: the same 20 ft down the hallway with and without the
//! vision workers looking for the Expecter's landmarks. Both hold the true pose in every map; the
//! map with landmarks ends several times smaller, its heading wedge too. Run under
//! `conditions/ideal.toml`: the figures compare the UMS's reductions with its growth where its
//! error model covers the sensors. Under the shipped worlds' camera and map errors the map loses
//! the truth on some seeds (docs/evaluation.md): not yet an invariant there. With the signs
//! ranged too (class II, `missions/uncertainty-signs.toml`) the map is smaller again, and loses
//! the truth no more often than with the bearings alone (ideal, nominal, dim, and harsh, whose
//! mount is three times worse than the robot's survey says, now that the UMS measures it at the
//! start: docs/evaluation.md); with the baseboard too (class III,
//! `missions/uncertainty-all-classes.toml`) smaller again, likewise.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use harvey_msgs::{LandmarkSighting, SightingKind, TruePose, UncertaintyMap};

/// Runs a mission; returns its maps (with the truth at each map's stamp checked inside).
fn run(mission: &str, tag: &str) -> Vec<UncertaintyMap> {
    let r = run_under(mission, "ideal", 1, tag);
    assert_eq!(r.outside, Vec::<u64>::new(), "{mission}: truth outside the map at these stamps (ns)");
    r.maps
}

/// A run's maps, the stamps of those the truth lay outside, its class II and III sightings
/// counted.
struct Maps {
    maps: Vec<UncertaintyMap>,
    outside: Vec<u64>,
    ranged: usize,
    lines: usize,
}

/// Runs a mission under `condition` at `seed`.
fn run_under(mission: &str, condition: &str, seed: u64, tag: &str) -> Maps {
    let out = common::run_mission_under(mission, condition, seed, tag);
    assert!(
        out.status.success() && out.stdout.contains("goal reached (10/10 steps)"),
        "{mission}: {}\n{}",
        out.stdout,
        out.stderr
    );
    let bytes = out.mcap.as_slice();
    let (mut maps, mut truth, mut ranged, mut lines) = (Vec::new(), Vec::new(), 0, 0);
    for m in mcap::MessageStream::new(bytes).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/ums/map" => maps.push(harvey_cdr::decode::<UncertaintyMap>(&m.data).expect("map")),
            "/sim/truth" => truth.push(harvey_cdr::decode::<TruePose>(&m.data).expect("truth")),
            "/vision/sightings" => {
                let s = harvey_cdr::decode::<LandmarkSighting>(&m.data).expect("sighting");
                ranged += usize::from(s.kind == SightingKind::BearingRange as u32);
                lines += usize::from(s.kind == SightingKind::GroundLine as u32);
            }
            _ => {}
        }
    }
    let outside = maps
        .iter()
        .filter(|m| {
            truth.iter().find(|t| t.header.stamp_ns == m.header.stamp_ns).is_some_and(|t| {
                let p = t.world_from_robot;
                !common::holds(m, p.x_m, p.y_m, p.heading_rad, 1e-6)
            })
        })
        .map(|m| m.header.stamp_ns)
        .collect();
    Maps { maps, outside, ranged, lines }
}

#[test]
fn landmarks_keep_the_map_several_times_smaller_than_dead_reckoning() {
    let with = run("missions/uncertainty.toml", "fig80");
    let without = run("missions/uncertainty-dead-reckoning.toml", "fig79");
    let (a, b) = (with.last().expect("maps"), without.last().expect("maps"));
    let wedge = |m: &UncertaintyMap| (m.heading_cw_rad + m.heading_ccw_rad).to_degrees();
    println!(
        "after 20 ft: with landmarks {:.4} m^2, wedge {:.1} deg; dead reckoning {:.4} m^2, wedge {:.1} deg",
        a.area_m2,
        wedge(a),
        b.area_m2,
        wedge(b)
    );
    assert!(b.area_m2 > 5.0 * a.area_m2, "{} vs {}", a.area_m2, b.area_m2);
    assert!(wedge(b) > 5.0 * wedge(a));
    // Without landmarks the area only ever grows.
    assert!(without.windows(2).all(|w| w[1].area_m2 >= w[0].area_m2 - 1e-12));
}

#[test]
fn each_class_of_landmark_added_keeps_the_map_smaller_and_loses_the_truth_no_more_often() {
    let missions = ["uncertainty", "uncertainty-signs", "uncertainty-all-classes"];
    // Under harsh the map need not end smaller: the bearings alone may shrink a map that has lost
    // the truth (seed 4: 7 maps without it, the signs' 0 a few % larger on average).
    let conditions =
        [("ideal", 1..=3, true), ("nominal", 1..=6, true), ("dim", 1..=3, true), ("harsh", 1..=5, false)];
    for (condition, seeds, smaller) in conditions {
        for seed in seeds {
            let runs: Vec<Maps> = missions
                .iter()
                .map(|m| run_under(&format!("missions/{m}.toml"), condition, seed, "fig80c"))
                .collect();
            let mean = |r: &Maps| r.maps.iter().map(|m| m.area_m2).sum::<f64>() / r.maps.len() as f64;
            for (m, r) in missions.iter().zip(&runs) {
                println!(
                    "{condition} s{seed} {m}: {:.4} m^2 after 20 ft, mean {:.4}; truth outside {} of {} maps; \
                     {} ranged, {} lines",
                    r.maps.last().expect("maps").area_m2,
                    mean(r),
                    r.outside.len(),
                    r.maps.len(),
                    r.ranged,
                    r.lines
                );
            }
            let [bearings, signs, all] = [&runs[0], &runs[1], &runs[2]];
            assert_eq!(
                (bearings.ranged, bearings.lines, signs.lines),
                (0, 0, 0),
                "each class only where asked"
            );
            assert!(
                signs.ranged > 10 && all.lines > 10,
                "{condition} s{seed}: {} ranged, {} lines",
                signs.ranged,
                all.lines
            );
            assert!(
                !smaller || (mean(signs) < mean(bearings) && mean(all) < mean(signs)),
                "{condition} s{seed}: not smaller"
            );
            for r in [signs, all] {
                assert!(r.outside.len() <= bearings.outside.len(), "{condition} s{seed}: {:?}", r.outside);
            }
        }
    }
}

#[test]
fn a_run_with_every_class_of_landmark_replays_identically_as_processes() {
    common::assert_replays("missions/uncertainty-all-classes.toml", "fig80rp", &[]);
}
