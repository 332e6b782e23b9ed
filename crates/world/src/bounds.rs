//! The range of every number of a world file, and caps on its lists: checked when a world is
//! loaded, before the consistency checks (`check.rs`) and before any service uses a number.
//! Each range is stated where it is checked; the shipped worlds sit well inside all of them.

use crate::{Region, Terrain, Wall, World};
use harvey_config::range::{OutOfRange, Range, check, check_all, check_len};
use harvey_config::spans::{KeyPath, Step};

/// Positions (walls, outlines, landmarks, doors, the start): a world of at most 10 km either way
/// from its origin. Larger numbers are typing mistakes, and 1e308 would make every distance
/// infinite (a start at x = 1e308 "reached" its goal with an error of 1e308 m).
pub(crate) const POSITION: Range = Range::within(10_000.0, "m");
/// Heights and sizes of things on the floor (walls, poles, the camera's mount): up to 100 m.
const HEIGHT: Range = Range::above(0.0, 100.0, "m");
/// Reflectances and colour factors: fractions of the light.
pub(crate) const FRACTION: Range = Range::closed(0.0, 1.0, "");
/// Headings, view intervals: two full turns either way.
const ANGLE: Range = Range::within(720.0, "deg");

/// Table 3 (002 §3.2) statistics. The paper's largest losses and spreads are 0.044 ft/ft,
/// 0.30 deg/ft and 0.018 deg/deg; the maxima are some ten times those, so that a file cannot make
/// the UMS's growth blow up: a loss of 1 per unit or more would run the robot backwards, and an
/// unbounded drift widens the swept arc without limit (`drift_deg_per_ft = inf` made the UMS's
/// arc enclosure, one vertex per 10 degrees, grow to 20 GB in a minute). At 5 deg/ft a 10 ft run
/// sweeps some 150 deg: 15 vertices per polygon vertex.
const LOSS_PER_UNIT: Range = Range::closed(0.0, 0.5, "per unit");
const INERTIAL_LOSS: Range = Range::closed(0.0, 1.0, "ft");
const SPREAD_PER_UNIT: Range = Range::closed(0.0, 0.5, "per unit");
const DRIFT: Range = Range::closed(0.0, 5.0, "deg/ft");
const SKITTER: Range = Range::closed(0.0, 0.1, "ft/deg");

/// How many walls, regions, locales, doors, meadows, landmarks, terrains, outline corners and
/// poles a file may hold: each service keeps them all and the ray casts visit every wall, so a
/// file could otherwise make a service allocate (and loop) without bound. The shipped worlds have
/// tens of walls and ten poles.
pub(crate) const MAX_ITEMS: usize = 10_000;
const MAX_REGIONS: usize = 1_000;
const MAX_POLES: f64 = 100.0;
/// The camera renders width x height pixels per frame: up to 4096 x 4096 (16 MB a mono frame).
const PIXELS: Range = Range::closed(1.0, 4096.0, "px");

fn root(key: &'static str) -> KeyPath {
    KeyPath::default().key(key)
}

/// Every number of `w` in its range, every list within its cap: the first that is not.
pub(crate) fn check_bounds(w: &World) -> Result<(), OutOfRange> {
    let start = root("start");
    check(&start.key("x_m"), w.start.x_m, &POSITION)?;
    check(&start.key("y_m"), w.start.y_m, &POSITION)?;
    check(&start.key("heading_deg"), w.start.heading_rad.to_degrees(), &ANGLE)?;
    check_robot(w)?;
    check_camera(w)?;
    check_map_error(w)?;
    let floor = root("floor");
    check(&floor.key("tile_m"), w.floor.tile_m, &HEIGHT)?;
    check_all(&floor.key("reflectance"), &w.floor.reflectance, &FRACTION)?;
    check(&floor.key("ceiling_reflectance"), w.floor.ceiling_reflectance, &FRACTION)?;
    check_len(&root("terrain"), w.terrain.len(), 1_000, "terrains")?;
    for (name, t) in &w.terrain {
        check_terrain(&root("terrain").then(Step::Name(name.clone())), t)?;
    }
    check_len(&root("wall"), w.walls.len(), MAX_ITEMS, "walls")?;
    for (i, wall) in w.walls.iter().enumerate() {
        check_wall(&root("wall").index(i), wall)?;
    }
    crate::bounds_topology::check_topology_bounds(w)?;
    if let Some(p) = &w.poles {
        crate::bounds_topology::check_poles(p)?;
    }
    Ok(())
}

fn check_robot(w: &World) -> Result<(), OutOfRange> {
    let (k, r) = (root("robot"), &w.robot);
    check(&k.key("speed_mps"), r.speed_mps, &Range::above(0.0, 10.0, "m/s"))?;
    check(&k.key("turn_rate_degps"), r.turn_rate_degps, &Range::above(0.0, 360.0, "deg/s"))?;
    check(&k.key("sonar_ring_radius_m"), r.sonar_ring_radius_m, &Range::closed(0.0, 5.0, "m"))?;
    // A beam is a cone round its axis: wider than 90 degrees each side it would look backwards.
    check(&k.key("sonar_beam_width_deg"), r.sonar_beam_width_deg, &Range::open(0.0, 90.0, "deg"))?;
    check(&k.key("sonar_specular_limit_deg"), r.sonar_specular_limit_deg, &Range::above(0.0, 90.0, "deg"))?;
    // The Polaroid sensor reaches 35 ft; a ray cast longer than 1000 ft finds nothing new.
    check(&k.key("sonar_max_range_ft"), r.sonar_max_range_ft, &Range::above(0.0, 1000.0, "ft"))?;
    // Noise beyond 10 ft would make every reading meaningless; chances are fractions.
    check(&k.key("sonar_range_sd_ft"), r.sonar_range_sd_ft, &Range::closed(0.0, 10.0, "ft"))?;
    check(&k.key("sonar_dropout"), r.sonar_dropout, &FRACTION)?;
    check(&k.key("sonar_crosstalk"), r.sonar_crosstalk, &FRACTION)?;
    check(&k.key("sonar_multipath"), r.sonar_multipath, &FRACTION)?;
    // An encoder coarser than a foot or 10 degrees per count could not drive a doorway.
    check(&k.key("encoder_count_ft"), r.encoder_count_ft, &Range::closed(0.0, 1.0, "ft"))?;
    check(&k.key("encoder_count_deg"), r.encoder_count_deg, &Range::closed(0.0, 10.0, "deg"))
}

fn check_camera(w: &World) -> Result<(), OutOfRange> {
    let (k, c) = (root("camera"), &w.camera);
    check(&k.key("width_px"), f64::from(c.width_px), &PIXELS)?;
    check(&k.key("height_px"), f64::from(c.height_px), &PIXELS)?;
    check(&k.key("focal_px"), c.focal_px, &Range::above(0.0, 100_000.0, "px"))?;
    check(&k.key("height_m"), c.height_m, &HEIGHT)?;
    // A pixel is illumination x reflectance, clamped to 255: beyond 10 000 every surface is white.
    check(&k.key("illumination"), c.illumination, &Range::closed(0.0, 10_000.0, ""))?;
    // The corners get 1 - vignetting of the centre's light: at 1 they would be black.
    check(&k.key("vignetting"), c.vignetting, &Range::below(0.0, 1.0, ""))?;
    check(&k.key("noise_sd"), c.noise_sd, &Range::closed(0.0, 1_000.0, "grey levels"))?;
    // A swing of the whole light either way: at 1 the scene would go black once a period.
    check(&k.key("illumination_drift"), c.illumination_drift, &Range::below(0.0, 1.0, ""))?;
    check(&k.key("illumination_period_s"), c.illumination_period_s, &Range::above(0.0, 1e6, "s"))?;
    // 000 §5.5 studies 0.001 and 0.010 rad; 0.2 rad (11 degrees) is a camera knocked off its mount.
    check(&k.key("misalignment_sd_rad"), c.misalignment_sd_rad, &Range::closed(0.0, 0.2, "rad"))?;
    if let Some([yaw, pitch]) = c.mount_error_rad {
        check(&k.key("mount_error_rad[0]"), yaw, &Range::within(0.2, "rad"))?;
        check(&k.key("mount_error_rad[1]"), pitch, &Range::within(0.2, "rad"))?;
    }
    check(&k.key("blur_px"), f64::from(c.blur_px), &Range::closed(0.0, 16.0, "px"))?;
    // 003's rover: 25 cm; a rig wider than the robot (2 m) is a typing mistake.
    match c.stereo_baseline_m {
        Some(b) => check(&k.key("stereo_baseline_m"), b, &Range::above(0.0, 2.0, "m")),
        None => Ok(()),
    }
}

fn check_map_error(w: &World) -> Result<(), OutOfRange> {
    let (k, e) = (root("map_error"), &w.map_error);
    // A map off by more than half a metre is another building.
    check(&k.key("position_sd_m"), e.position_sd_m, &Range::closed(0.0, 0.5, "m"))?;
    check(&k.key("reflectance_sd"), e.reflectance_sd, &Range::closed(0.0, 1.0, ""))?;
    let (k, s) = (root("survey"), &w.survey);
    check(&k.key("position_sd_m"), s.position_sd_m, &Range::closed(0.0, 0.5, "m"))?;
    check(&k.key("calibration_sd_rad"), s.calibration_sd_rad, &Range::closed(0.0, 0.2, "rad"))
}

fn check_terrain(k: &KeyPath, t: &Terrain) -> Result<(), OutOfRange> {
    check(&k.key("translational_loss_ft_per_ft"), t.translational_loss_ft_per_ft, &LOSS_PER_UNIT)?;
    check(&k.key("inertial_loss_ft"), t.inertial_loss_ft, &INERTIAL_LOSS)?;
    check(&k.key("translational_sd_ft_per_ft"), t.translational_sd_ft_per_ft, &SPREAD_PER_UNIT)?;
    check(&k.key("drift_deg_per_ft"), t.drift_deg_per_ft, &DRIFT)?;
    check(&k.key("drift_sd_deg_per_ft"), t.drift_sd_deg_per_ft, &DRIFT)?;
    check(&k.key("rotational_loss_deg_per_deg"), t.rotational_loss_deg_per_deg, &LOSS_PER_UNIT)?;
    check(&k.key("rotational_sd_deg_per_deg"), t.rotational_sd_deg_per_deg, &SPREAD_PER_UNIT)?;
    check(&k.key("skitter_ft_per_deg"), t.skitter_ft_per_deg, &SKITTER)?;
    check(&k.key("skitter_sd_ft_per_deg"), t.skitter_sd_ft_per_deg, &SKITTER)
}

fn check_wall(k: &KeyPath, wall: &Wall) -> Result<(), OutOfRange> {
    check_all(&k.key("from"), &wall.from, &POSITION)?;
    check_all(&k.key("to"), &wall.to, &POSITION)?;
    check(&k.key("height_m"), wall.height_m, &HEIGHT)?;
    check(&k.key("reflectance"), wall.reflectance, &FRACTION)?;
    check_all(&k.key("colour"), &wall.colour, &FRACTION)?;
    check_len(&k.key("region"), wall.regions.len(), MAX_REGIONS, "regions")?;
    for (j, r) in wall.regions.iter().enumerate() {
        check_region(&k.key("region").index(j), r)?;
    }
    Ok(())
}

fn check_region(k: &KeyPath, r: &Region) -> Result<(), OutOfRange> {
    check_all(&k.key("along_m"), &r.along_m, &POSITION)?;
    check_all(&k.key("height_m"), &r.height_m, &Range::closed(0.0, 100.0, "m"))?;
    check(&k.key("reflectance"), r.reflectance, &FRACTION)?;
    check_all(&k.key("colour"), &r.colour, &FRACTION)
}

/// The pole count as a number, for its range.
pub(crate) const POLE_COUNT: Range = Range::closed(0.0, MAX_POLES, "poles");
