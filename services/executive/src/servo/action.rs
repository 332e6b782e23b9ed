//! Action-level perceptual servoing (000 §5.5): after each increment of a move, the heading error
//! follows from where a landmark appears in the image, `h = atan((Y - e)/(X + q)) + atan(-x/f)`,
//! and the robot turns towards a point `D` ahead on the intended line:
//! `correction = -(h + atan(m sin h / (D + m sin h tan h)))`. A known camera misalignment is
//! taken off the measured bearing. The `_off_line` forms take the robot's whole offset from the
//! line (tracked increment by increment) instead of one increment's.

/// The camera and the steering aim.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoParams {
    /// Focal length (pixels).
    pub focal_px: f64,
    /// Camera yaw relative to the direction of motion (radians, left positive), as calibrated.
    pub misalignment_rad: f64,
    /// Distance ahead on the intended line to steer for (m).
    pub aim_m: f64,
}

/// The heading error after an increment of `m` metres, from a landmark expected at `(X, Y)` in
/// the frame of the intended line at the robot's expected position (X ahead, Y left) and seen
/// at image `x` pixels left of the image centre. `e` and `q` (the offset from the line and the
/// shortfall) are estimated from the heading error itself, refined twice.
pub fn heading_error(landmark: [f64; 2], x_left_px: f64, m: f64, p: &ServoParams) -> f64 {
    let [x_l, y_l] = landmark;
    // The bearing measured in the robot frame, less the camera's own yaw.
    let bearing = (x_left_px / p.focal_px).atan() + p.misalignment_rad;
    let mut h = y_l.atan2(x_l) - bearing;
    for _ in 0..2 {
        let (e, q) = (m * h.sin(), m * h.sin() * h.tan());
        h = (y_l - e).atan2(x_l + q) - bearing;
    }
    h
}

/// The turn that puts a robot with heading error `h`, `m` metres into its increment, on course
/// for the point `aim_m` ahead on the intended line.
pub fn correction(h: f64, m: f64, p: &ServoParams) -> f64 {
    let e = m * h.sin();
    -(h + (e / (p.aim_m + e * h.tan())).atan())
}

/// The heading error when the robot's offset from the intended line is known as a whole
/// (`offset_m`, left positive) rather than taken as this increment's `m sin h` alone: the
/// landmark at `(X, Y)` from the expected position is then at `(X, Y - offset)` from the robot.
pub fn heading_error_off_line(landmark: [f64; 2], x_left_px: f64, offset_m: f64, p: &ServoParams) -> f64 {
    let bearing = (x_left_px / p.focal_px).atan() + p.misalignment_rad;
    (landmark[1] - offset_m).atan2(landmark[0]) - bearing
}

/// The turn that puts a robot `offset_m` off the line with heading error `h` on course for
/// the point `aim_m` ahead on it: [`correction`] with the whole offset.
pub fn correction_off_line(h: f64, offset_m: f64, p: &ServoParams) -> f64 {
    -(h + (offset_m / (p.aim_m + offset_m * h.tan())).atan())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Drives 40 ft (12.19 m) down a line in 2 ft increments with a steady curve (the open-loop
    /// drift of 000 §5.5) and returns the lateral deviation (m) after each increment.
    fn run(servoed: bool, misalignment: f64) -> Vec<f64> {
        // The paper gives no aim distance: two increments ahead.
        let p = ServoParams { focal_px: 554.0, misalignment_rad: misalignment, aim_m: 1.2 };
        let step = 0.6096; // 2 ft
        let landmark = [20.0, 0.4]; // a door jamb beyond the end of the run, just off the line
        let (mut x, mut y, mut th) = (0.0f64, 0.0f64, 0.0f64);
        let curve = 0.004; // radians of heading gained per increment, unservoed
        let mut dev = Vec::new();
        for _ in 0..20 {
            // The increment: a straight move at the current heading that curves a little.
            let mid = th + curve / 2.0;
            (x, y, th) = (x + step * mid.cos(), y + step * mid.sin(), th + curve);
            dev.push(y);
            if servoed {
                // What the camera sees: the landmark's bearing from the true pose (left
                // positive), through a camera yawed by the (uncalibrated) misalignment.
                let bearing = (landmark[1] - y).atan2(landmark[0] - x) - th - 0.001;
                let x_left = p.focal_px * bearing.tan();
                // Expected: on the line at x, heading along it.
                let h = heading_error([landmark[0] - x, landmark[1]], x_left, step, &p);
                th += correction(h, step, &p);
            }
        }
        dev
    }

    #[test]
    fn servoing_holds_the_line_where_open_loop_drifts_off_it() {
        let inch = harvey_geometry::INCH;
        let open = run(false, 0.0);
        let servoed = run(true, 0.001);
        let worst = servoed.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        println!(
            "unservoed at 10, 20 ft: {:.2} {:.2} in; servoed worst {:.3} in",
            open[4] / inch,
            open[9] / inch,
            worst / inch
        );
        // 000 Fig. 11: open loop over 2 in by 18-20 ft; servoed within 0.3 in over 40 ft.
        assert!(open[9].abs() > 2.0 * inch, "{}", open[9] / inch);
        assert!(worst < 0.3 * inch, "{}", worst / inch);
    }

    #[test]
    fn no_error_no_correction_and_the_signs_turn_back() {
        let p = ServoParams { focal_px: 554.0, misalignment_rad: 0.0, aim_m: 3.0 };
        // On the line, heading along it: the landmark is where it should be.
        let x_left = 554.0 * (0.4f64 / 10.0).atan().tan();
        assert!(heading_error([10.0, 0.4], x_left, 0.6, &p).abs() < 1e-9);
        // Heading 0.02 rad left: the landmark appears further right, the error is +0.02, and
        // the correction turns right by more than that (back towards the line).
        let left = 554.0 * ((0.4f64 / 10.0).atan() - 0.02).tan();
        let h = heading_error([10.0, 0.4], left, 0.0, &p);
        assert!((h - 0.02).abs() < 1e-9, "{h}");
        let c = correction(h, 0.6, &p);
        assert!(c < -0.02, "{c}");
    }
}
