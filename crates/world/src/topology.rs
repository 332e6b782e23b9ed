//! The world's topology and perception data (000 §3.2, 002 §4): locales in a part-of hierarchy
//! joined by doorways, meadows (areas of one terrain with the landmarks seen from them), and
//! landmarks with their class, activation and perceptual strategy.

use serde::Deserialize;

/// A locale: a parcel of space with meaning for navigation (a building, a hallway, a room).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Locale {
    pub name: String,
    /// The locale this one is part of (000 §3.2: part/subpart arcs).
    pub part_of: Option<String>,
    /// Free-space footprint in the world frame, counter-clockwise; none for a pure grouping.
    #[serde(default)]
    pub outline: Vec<[f64; 2]>,
}

/// A doorway: the transition arc between two locales.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Door {
    pub between: [String; 2],
    /// Centre of the opening on the floor.
    pub at: [f64; 2],
    pub width_m: f64,
}

/// Landmark classes of 002 §3.4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum LandmarkClass {
    /// A vertical line (a door jamb, a building corner, a lamppost): a ray from the landmark.
    I,
    /// A point of known height: range and bearing.
    II,
    /// A line on the ground plane (a baseboard, a path edge): heading and lateral position.
    III,
}

/// How a landmark is to be perceived (the algorithm the vision workers run for it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    LineFinder,
    RegionSegmenter,
    Correlation,
    Hough,
}

/// A landmark the robot may look for.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Landmark {
    pub name: String,
    pub class: LandmarkClass,
    /// Class I: the line's foot; class II: the point; class III: one end (z = 0). World frame.
    pub position_m: [f64; 3],
    /// Class III: the other end of the ground line.
    pub to_m: Option<[f64; 3]>,
    /// Class I: the line's length upwards from its foot.
    #[serde(default)]
    pub height_m: f64,
    /// How well the world model knows where the landmark is (standard deviation, metres).
    #[serde(default)]
    pub position_sd_m: f64,
    /// Seen only within this distance of the robot.
    pub activation_range_m: f64,
    /// Seen only while the robot's heading lies within this interval (degrees, counter-clockwise).
    pub view_headings_deg: [f64; 2],
    pub strategy: Strategy,
}

/// An area of one terrain and the landmarks to look for while in it (002 §4).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Meadow {
    pub name: String,
    pub terrain: String,
    pub outline: Vec<[f64; 2]>,
    #[serde(default)]
    pub landmarks: Vec<String>,
    /// The ground's look here: reflectances of its checker pattern (tiles, slabs, tufts);
    /// the world's `[floor]` where not given.
    pub floor_reflectance: Option<[f64; 2]>,
}

/// Whether `p` lies inside the polygon `poly` (even-odd rule; points on an edge may go either way).
pub fn contains(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let mut j = poly.len().wrapping_sub(1);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0] {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// Area of a simple polygon (positive when counter-clockwise).
pub fn signed_area(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    (0..n).map(|i| poly[i][0] * poly[(i + 1) % n][1] - poly[(i + 1) % n][0] * poly[i][1]).sum::<f64>() / 2.0
}

impl Landmark {
    /// Whether a robot at `(x, y)` heading `heading_deg` activates this landmark (002 §4).
    pub fn active_from(&self, x: f64, y: f64, heading_deg: f64) -> bool {
        let d = (self.position_m[0] - x).hypot(self.position_m[1] - y);
        let [lo, hi] = self.view_headings_deg;
        let h = lo + (heading_deg - lo).rem_euclid(360.0);
        d <= self.activation_range_m && h <= hi
    }

    /// The point correlation looks for (000 §5.3): a class I line's middle, else its position.
    pub fn point(&self) -> [f64; 3] {
        let p = self.position_m;
        match self.class {
            LandmarkClass::I => [p[0], p[1], p[2] + self.height_m / 2.0],
            _ => p,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_contain_and_measure() {
        let square = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        assert!(contains(&square, [1.0, 1.0]));
        assert!(!contains(&square, [3.0, 1.0]));
        assert!((signed_area(&square) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn activation_needs_range_and_heading() {
        let l = Landmark {
            name: "l".into(),
            class: LandmarkClass::II,
            position_m: [10.0, 0.0, 1.5],
            to_m: None,
            height_m: 0.0,
            position_sd_m: 0.0,
            activation_range_m: 5.0,
            view_headings_deg: [-45.0, 45.0],
            strategy: Strategy::Correlation,
        };
        assert!(l.active_from(6.0, 0.0, 10.0));
        assert!(l.active_from(6.0, 0.0, 350.0), "350 deg is -10 deg");
        assert!(!l.active_from(6.0, 0.0, 90.0), "facing away");
        assert!(!l.active_from(2.0, 0.0, 0.0), "out of range");
    }
}
