//! What the camera renders agrees with the calibration the Expecter uses: landmarks appear
//! within 0.5 px of their projection, and regions' intensities stand in the ratio of their
//! reflectances (pixel = illumination x reflectance).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_msgs::Encoding;
use harvey_render::Renderer;
use harvey_world::{Pose2, World};

fn hallway() -> World {
    harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads")
}

fn render(w: &World, pose: Pose2) -> Vec<u8> {
    let mut r = Renderer::new(w, 640, 480, Encoding::Mono8);
    let mut img = vec![0u8; r.frame_bytes()];
    r.render(w, pose, &mut img).expect("renders");
    img
}

#[test]
fn a_door_jamb_appears_where_the_calibration_projects_it() {
    let w = hallway();
    let jamb = w.landmark("lab-door-east-jamb").expect("landmark");
    for pose in [Pose2::new(2.0, 0.0, 0.3), Pose2::new(1.0, -0.4, 0.5), Pose2::new(0.0, 0.3, 0.2)] {
        // A point on the jamb at 1 m height, and the row it projects to.
        let p = [jamb.position_m[0], jamb.position_m[1], 1.0];
        let [u, v] = w.camera.project(640, 480, pose, p).expect("in view");
        assert!((0.0..640.0).contains(&u) && (0.0..480.0).contains(&v), "{pose:?}: ({u}, {v})");
        let img = render(&w, pose);
        let row = &img[v as usize * 640..(v as usize + 1) * 640];
        // The jamb is where the wall's intensity gives way to the view through the doorway:
        // the pixel boundary between two differing neighbours nearest the projection.
        let edge = (1..640)
            .filter(|&k| row[k - 1] != row[k])
            .min_by(|a, b| (*a as f64 - u).abs().total_cmp(&(*b as f64 - u).abs()));
        let edge = edge.expect("an edge in the row") as f64;
        assert!((edge - u).abs() <= 0.5, "{pose:?}: edge at {edge}, projection {u:.3}");
    }
}

#[test]
fn the_sign_is_centred_on_its_projection_with_the_reflectance_ratio() {
    let w = hallway();
    let sign = w.landmark("office-sign").expect("landmark");
    let pose = Pose2::new(12.4, -0.9, std::f64::consts::FRAC_PI_2);
    let img = render(&w, pose);
    let lit = |r: f64| (w.camera.illumination * r).round() as u8;
    let (mut n, mut su, mut sv) = (0.0, 0.0, 0.0);
    for (i, &p) in img.iter().enumerate() {
        if p == lit(0.95) {
            n += 1.0;
            su += (i % 640) as f64 + 0.5;
            sv += (i / 640) as f64 + 0.5;
        }
    }
    assert!(n > 1000.0, "the sign covers {n} pixels");
    let [u, v] = w.camera.project(640, 480, pose, sign.position_m).expect("in view");
    assert!(
        (su / n - u).abs() <= 0.5 && (sv / n - v).abs() <= 0.5,
        "centroid ({}, {}) vs projection ({u}, {v})",
        su / n,
        sv / n
    );
    // The wall right beside it: intensity ratio = reflectance ratio, to the rounding of 8 bits.
    let wall_px = img[v as usize * 640 + (u as usize + 150)];
    assert_eq!(wall_px, lit(0.70));
    let ratio = f64::from(lit(0.95)) / f64::from(wall_px);
    assert!((ratio - 0.95 / 0.70).abs() < 0.01, "{ratio}");
}
