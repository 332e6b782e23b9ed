//! Tests of the mount measured at the start: sightings made through a turned and tilted camera
//! give the mount back, and corrected, read as through a true one.

use harvey_msgs::{Header, LandmarkSighting, SightingKind};

use super::{Gate, Mount, untilted_line};
use crate::map::Map;

use crate::tests::{config, hallway, odo};

const GATE: Gate = Gate { heading_rad: 0.003, area_m2: 1e-4 };

/// What a camera turned `yaw` left and tilted `pitch` down on its mount at `map`'s centre makes
/// of landmark `i`: its bearing and, for a point above the camera, the range its row gives.
fn seen(
    w: &harvey_world::World,
    map: &Map,
    i: usize,
    kind: SightingKind,
    yaw: f64,
    pitch: f64,
) -> LandmarkSighting {
    let l = &w.landmarks[i];
    let (dx, dy) = (l.position_m[0] - map.centre[0], l.position_m[1] - map.centre[1]);
    let bearing = dy.atan2(dx) - map.heading_rad;
    let above = l.position_m[2] - w.camera.height_m;
    let seen_bearing = bearing - yaw;
    // The worker ranges along the camera's axis, turned by the mount, and back by its bearing.
    let depth = dx.hypot(dy) * seen_bearing.cos();
    let row = ((above / depth).atan() + pitch).tan();
    LandmarkSighting {
        header: Header::new(1, 0),
        landmark_index: i as u32,
        kind: kind as u32,
        a: seen_bearing,
        a_sd: 0.002,
        b: above / row / seen_bearing.cos(),
        b_sd: 0.5,
        ..Default::default()
    }
}

fn truth(w: &harvey_world::World, map: &Map, i: usize) -> (f64, f64) {
    let l = &w.landmarks[i];
    let (dx, dy) = (l.position_m[0] - map.centre[0], l.position_m[1] - map.centre[1]);
    (dy.atan2(dx) - map.heading_rad, dx.hypot(dy))
}

#[test]
fn sightings_at_the_start_measure_the_mount_and_corrected_read_as_through_a_true_one() {
    let w = hallway();
    let start = Map::exact(w.start.x_m, w.start.y_m, w.start.heading_rad);
    let (yaw, pitch) = (0.012, -0.009);
    let sign = w.landmarks.iter().position(|l| l.position_m[2] > w.camera.height_m + 0.5).expect("a sign");
    let mut m = Mount::default();
    assert_eq!(m.estimate(), (0.0, 0.0), "nothing measured: nothing taken off");
    m.observe(&w, &start, GATE, &seen(&w, &start, sign, SightingKind::BearingRange, yaw, pitch));
    let (y, p) = m.estimate();
    assert!((y - yaw).abs() < 1e-9 && (p - pitch).abs() < 1e-9, "measured {y} {p}");
    // Further on, a sighting through the same camera is corrected to the truth.
    let on = Map::exact(w.start.x_m + 3.0, w.start.y_m, w.start.heading_rad);
    let c = m.correct(&w, &seen(&w, &on, sign, SightingKind::BearingRange, yaw, pitch));
    let (bearing, range) = truth(&w, &on, sign);
    assert!(
        (c.a - bearing).abs() < 1e-9 && (c.b - range).abs() < 1e-6,
        "{} {} against {bearing} {range}",
        c.a,
        c.b
    );
    // A ground line's relative heading turns the other way; its offset stays.
    let line =
        LandmarkSighting { kind: SightingKind::GroundLine as u32, a: 0.1, b: 0.7, ..Default::default() };
    let turned = Mount { yaws: vec![yaw], pitches: Vec::new() };
    let c = turned.correct(&w, &line);
    assert!((c.a - (0.1 - yaw)).abs() < 1e-12 && c.b == 0.7);
}

#[test]
fn only_sightings_while_the_map_pins_the_pose_measure_it_and_the_median_outvotes_a_false_match() {
    let w = hallway();
    let start = Map::exact(w.start.x_m, w.start.y_m, w.start.heading_rad);
    let sign = w.landmarks.iter().position(|l| l.position_m[2] > w.camera.height_m + 0.5).expect("a sign");
    let mut m = Mount::default();
    let mut loose = start.clone();
    loose.cw_rad = 0.01;
    m.observe(&w, &loose, GATE, &seen(&w, &loose, sign, SightingKind::Bearing, 0.02, 0.0));
    assert_eq!(m.estimate(), (0.0, 0.0), "a wedge wider than the survey's mount measures no yaw");
    m.observe(&w, &loose, GATE, &seen(&w, &loose, sign, SightingKind::BearingRange, 0.02, 0.004));
    assert_eq!(m.measures(), (0, 1), "but the pitch");
    m = Mount::default();
    let mut wide = start.clone();
    wide.polygon = vec![[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]];
    m.observe(&w, &wide, GATE, &seen(&w, &wide, sign, SightingKind::BearingRange, 0.02, 0.004));
    assert_eq!(m.measures(), (0, 0), "a map wider than the survey's map error measures nothing");
    for yaw in [0.004, 0.005, 0.2] {
        m.observe(&w, &start, GATE, &seen(&w, &start, sign, SightingKind::Bearing, yaw, 0.0));
    }
    assert!((m.estimate().0 - 0.005).abs() < 1e-9, "{:?}", m.estimate());
    assert_eq!(m.estimate().1, 0.0, "bearings alone say nothing of the pitch");
    let missed = LandmarkSighting { kind: SightingKind::NotFound as u32, ..Default::default() };
    assert_eq!(m.correct(&w, &missed), missed);
}

#[test]
fn a_ground_line_seen_through_a_pitched_camera_is_taken_back_to_the_level_one() {
    let w = hallway();
    let below = w.camera.height_m;
    let (heading, offset) = (0.04f64, 0.9f64);
    // The true line y = a + b x; two of its points as a camera pitched `pitch` down ranges them.
    let (b, a) = (-heading.tan(), -offset * heading.tan().hypot(1.0));
    for pitch in [0.01, -0.01] {
        let seen: Vec<[f64; 2]> = [3.0, 5.0]
            .iter()
            .map(|&x| {
                let far = below / ((below / x).atan() - pitch).tan();
                [far, (a + b * x) * far / x]
            })
            .collect();
        let sb = (seen[1][1] - seen[0][1]) / (seen[1][0] - seen[0][0]);
        let sa = seen[0][1] - sb * seen[0][0];
        let tilted = (-sb.atan(), -sa / sb.hypot(1.0));
        assert!((tilted.0 - heading).abs() > 0.005, "the pitch turns the line: {tilted:?}");
        let (h, o) = untilted_line(&w, below, pitch, tilted);
        assert!((h - heading).abs() < 5e-4 && (o - offset).abs() < 0.002, "{pitch}: {h} {o}");
    }
    assert_eq!(untilted_line(&w, below, 0.0, (heading, offset)), (heading, offset));
}

#[test]
fn a_baseboard_is_untilted_at_its_top_and_a_sign_pitched_past_the_horizon_keeps_its_bearing_only() {
    let w = hallway();
    let (i, board) =
        w.landmarks.iter().enumerate().find(|(_, l)| l.name == "north-baseboard").expect("board");
    let top = w.wall_band(board).map(|(_, r)| r.height_m[1]).expect("a baseboard");
    assert!(top > 0.05, "the band's top, not the floor: {top}");
    let pitched = Mount { yaws: Vec::new(), pitches: vec![0.01] };
    let line = LandmarkSighting {
        landmark_index: i as u32,
        kind: SightingKind::GroundLine as u32,
        a: 0.03,
        b: 1.2,
        ..Default::default()
    };
    let c = pitched.correct(&w, &line);
    assert_eq!((c.a, c.b), untilted_line(&w, w.camera.height_m - top, 0.01, (0.03, 1.2)));
    let sign = w.landmarks.iter().position(|l| l.position_m[2] > w.camera.height_m + 0.5).expect("a sign");
    let far = LandmarkSighting {
        landmark_index: sign as u32,
        kind: SightingKind::BearingRange as u32,
        a: 0.01,
        b: 40.0,
        b_sd: 5.0,
        ..Default::default()
    };
    let c = Mount { yaws: Vec::new(), pitches: vec![0.2] }.correct(&w, &far);
    assert_eq!((c.kind, c.a), (SightingKind::Bearing as u32, 0.01), "no range from a row past the horizon");
}

#[test]
fn a_ums_measuring_the_mount_takes_it_from_a_sighting_at_the_start_and_keeps_it_in_its_state() {
    let w = hallway();
    let mut u = crate::Ums::new(w.clone(), config(Some(GATE)));
    u.on_odometry(&odo(50, 0.0)).expect("ok");
    let start = Map::exact(w.start.x_m, w.start.y_m, w.start.heading_rad);
    let corner = w.landmarks.iter().position(|l| l.name == "end-wall-corner").expect("corner");
    let mut s = seen(&w, &start, corner, SightingKind::Bearing, 0.008, 0.0);
    s.header = Header::new(1, 50_000_000);
    // Measured whether or not the reduction takes it (the start's map is a point).
    let _ = u.on_sighting(&s);
    assert!((u.mount.estimate().0 - 0.008).abs() < 1e-9, "{:?}", u.mount.estimate());
    // The measure travels in the checkpoint's state.
    let mut v = crate::Ums::new(w.clone(), config(Some(GATE)));
    v.restore(u.state());
    assert_eq!(v.mount, u.mount);
    // Further on, with the map's wedge wider than the survey's mount, nothing more is measured.
    for k in 2..=20 {
        u.on_odometry(&odo(k * 50, k as f64 * 0.1)).expect("ok");
    }
    let mut later = seen(&w, &start, corner, SightingKind::Bearing, 0.05, 0.0);
    later.header = Header::new(2, 1_000_000_000);
    let _ = u.on_sighting(&later);
    assert_eq!(u.mount.measures(), (1, 0));
    // A UMS told not to measure takes the sightings as they come.
    let mut off = crate::Ums::new(w, config(None));
    off.on_odometry(&odo(50, 0.0)).expect("ok");
    let _ = off.on_sighting(&s);
    assert_eq!(off.mount.measures(), (0, 0));
}
