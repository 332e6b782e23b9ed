//! The camera mount measured at the start (a boresight check, as the executive's
//! `calibrate_mount` does for a servoed leg): while the map still pins the pose tighter than the
//! mount is known, every sighting's bearing against the one the map predicts is the mount's yaw,
//! and a class II sighting's range against the predicted one its pitch (002 §3.4: the range comes
//! from the row, through the point's height above the camera). The median of those measured is
//! then taken off every later sighting, so that a mount further off than the robot's survey says
//! does not bias every bearing and range alike, which no reduction can tell from a pose error.

use harvey_geometry::median;
use harvey_msgs::{LandmarkSighting, SightingKind};
use harvey_world::World;

use crate::map::{Map, wrap};

/// The mount's yaw (left positive) and pitch (down positive) measured so far, radians.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mount {
    yaws: Vec<f64>,
    pitches: Vec<f64>,
}

/// A yaw or pitch measured past this (rad) is a false match, not the mount: the world's bound on
/// a mount's error, a camera knocked off its mount (`harvey_world` bounds).
const MAX_MOUNT_RAD: f64 = 0.2;

/// When a sighting measures the mount: the map's area within `area_m2` (the position known to
/// the survey's map error), and for the yaw its heading wedge within `heading_rad` too (the
/// survey's calibration: the heading is then known better than the mount).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gate {
    pub heading_rad: f64,
    pub area_m2: f64,
}

/// The point's elevation above the camera's level, seen `depth_m` ahead (`above_m` above it).
fn elevation(above_m: f64, depth_m: f64) -> f64 {
    (above_m / depth_m).atan()
}

impl Mount {
    /// The yaw and pitch measured so far (zero where nothing measured them).
    pub fn estimate(&self) -> (f64, f64) {
        (median(&self.yaws).unwrap_or(0.0), median(&self.pitches).unwrap_or(0.0))
    }

    /// How many sightings have measured the yaw and the pitch.
    pub fn measures(&self) -> (usize, usize) {
        (self.yaws.len(), self.pitches.len())
    }

    /// Takes `s` as a measure of the mount if `map` (the map at its stamp) passes `gate`.
    pub fn observe(&mut self, world: &World, map: &Map, gate: Gate, s: &LandmarkSighting) {
        let Some(l) = world.landmarks.get(s.landmark_index as usize) else { return };
        let kind = SightingKind::from_raw(s.kind);
        let point = matches!(kind, Some(SightingKind::Bearing | SightingKind::BearingRange));
        if !point || map.area_m2() > gate.area_m2 {
            return;
        }
        let (dx, dy) = (l.position_m[0] - map.centre[0], l.position_m[1] - map.centre[1]);
        let bearing = wrap(dy.atan2(dx) - map.heading_rad);
        // The heading turns the bearings as the yaw does: only while it is known better.
        if map.cw_rad + map.ccw_rad <= gate.heading_rad {
            // A mount turned left sees everything further right: at a smaller bearing.
            let yaw = wrap(bearing - s.a);
            if yaw.abs() <= MAX_MOUNT_RAD {
                self.yaws.push(yaw);
            }
        }
        let above_m = l.position_m[2] - world.camera.height_m;
        // Along the camera's axis (the worker ranges by it), the camera turned by the mount.
        let depth = dx.hypot(dy) * s.a.cos();
        if kind == Some(SightingKind::BearingRange) && s.b > 0.0 && above_m != 0.0 && depth > 0.0 {
            // A mount pitched down lifts everything in the image: the row reads a point above
            // the camera as higher, so nearer, than it is.
            let pitch = elevation(above_m, s.b * s.a.cos()) - elevation(above_m, depth);
            if pitch.abs() <= MAX_MOUNT_RAD {
                self.pitches.push(pitch);
            }
        }
    }

    /// `s` with the mount measured so far taken off: its bearing (class I and II) or relative
    /// heading (class III) turned by the yaw, a class II range taken again from its row with the
    /// pitch taken off.
    pub fn correct(&self, world: &World, s: &LandmarkSighting) -> LandmarkSighting {
        let (yaw, pitch) = self.estimate();
        let mut c = *s;
        match SightingKind::from_raw(s.kind) {
            Some(SightingKind::Bearing) => c.a = s.a + yaw,
            Some(SightingKind::BearingRange) => {
                c.a = s.a + yaw;
                let above_m = world
                    .landmarks
                    .get(s.landmark_index as usize)
                    .map_or(0.0, |l| l.position_m[2] - world.camera.height_m);
                let e = elevation(above_m, s.b * s.a.cos()) - pitch;
                if above_m != 0.0 && s.b > 0.0 && e * above_m.signum() > 1e-4 {
                    // The depth along the camera's axis, and the range by the camera's bearing.
                    let depth = above_m / e.tan();
                    c.b = depth / s.a.cos();
                    c.b_sd = s.b_sd * c.b / s.b;
                } else if pitch != 0.0 {
                    // The pitch leaves the point on the horizon or past it: its row gives no
                    // range, only its column a bearing.
                    (c.kind, c.b, c.b_sd) = (SightingKind::Bearing as u32, 0.0, 0.0);
                }
            }
            Some(SightingKind::GroundLine) => {
                // The edge the worker ranges: a baseboard's top, or the floor.
                let below_m = world.landmarks.get(s.landmark_index as usize).map_or(0.0, |l| {
                    world.camera.height_m - world.wall_band(l).map_or(l.position_m[2], |(_, r)| r.height_m[1])
                });
                (c.a, c.b) = untilted_line(world, below_m, pitch, (s.a, s.b));
                // The line's direction turns with the camera; its distance from it does not.
                c.a -= yaw;
            }
            Some(SightingKind::NotFound) | None => {}
        }
        c
    }
}

/// A ground line `below_m` under the camera seen through a mount pitched `pitch` (rad, down
/// positive) as `(heading, offset)` (the robot's heading less the line's direction, its distance
/// from the line, left positive), as a level camera would have seen it. The recogniser ranges
/// each point by its row: pitched down, the floor looks further away than it is, each point by
/// its own depth's factor. The line is taken again through two of its points, at the nearest
/// floor in view (the image's bottom row) and twice as far; unchanged for an edge at the
/// camera's height or a line across the view.
fn untilted_line(world: &World, below_m: f64, pitch: f64, (heading, offset): (f64, f64)) -> (f64, f64) {
    let cam = &world.camera;
    let half_rows = f64::from(cam.height_px) / 2.0;
    let slope = -heading.tan();
    let intercept = -offset * slope.hypot(1.0);
    if below_m <= 0.0 || pitch == 0.0 || heading.cos().abs() < 0.1 {
        return (heading, offset);
    }
    let nearest = cam.focal_px * below_m / half_rows;
    let [p, q] = [nearest, 2.0 * nearest].map(|seen| {
        let depth = below_m / ((below_m / seen).atan() + pitch).tan();
        [depth, (intercept + slope * seen) * depth / seen]
    });
    if ![p[0], q[0]].iter().all(|d| d.is_finite() && *d > 0.0) || q[0] <= p[0] {
        return (heading, offset);
    }
    let slope = (q[1] - p[1]) / (q[0] - p[0]);
    let intercept = p[1] - slope * p[0];
    (-slope.atan(), -intercept / slope.hypot(1.0))
}

impl crate::Ums {
    /// `s` with the camera mount taken off, once it has measured the mount if the map at its
    /// stamp allows (`mount.rs`); as it is when the UMS does not measure the mount.
    pub(crate) fn calibrated(&mut self, s: &LandmarkSighting) -> LandmarkSighting {
        let Some(gate) = self.config.mount_gate else { return *s };
        let before = self.mount.measures();
        // Only against the map at its stamp (one older than the history is refused anyway).
        if let Some(i) = self.history.iter().rposition(|(t, ..)| *t <= s.header.stamp_ns) {
            self.mount.observe(&self.world, &self.history[i].1, gate, s);
        }
        if self.mount.measures() != before {
            let ((yaw, pitch), (yaws, pitches)) = (self.mount.estimate(), self.mount.measures());
            let landmark = &self.world.landmarks[s.landmark_index as usize].name;
            tracing::info!(
                landmark,
                yaw_mrad = yaw * 1e3,
                pitch_mrad = pitch * 1e3,
                yaws,
                pitches,
                "mount measured"
            );
        }
        self.mount.correct(&self.world, s)
    }
}

#[cfg(test)]
#[path = "mount_tests.rs"]
mod tests;
