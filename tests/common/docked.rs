//! What both docking tests (the mission's processes and the closed loop in one process) check
//! of a finished docking run: 004 §4.2.2's acceptor trace, the mark and squareness.

use harvey_geometry::INCH;
use harvey_msgs::Pose2;

/// How far `end` is from the mark (in): 0.5 m out from the dock face's centre (13.6, 0).
pub fn off_mark_in(end: Pose2) -> f64 {
    (end.x_m - 13.1).hypot(end.y_m) / INCH
}

/// Asserts the acceptor's `trace` (each state once per visit) and the run's final pose `end`.
pub fn assert_docked(trace: &[u32], end: Pose2) {
    // 004 §4.2.2's run: recognised (q1 -> q2), tracking lost to the cart (q2 -> q1) and regained,
    // then sonar positioning (q3) and docked (q4). Under the worlds' real-camera imperfections the
    // acceptor may go round q0-q1-q2 more than once before the cart has passed.
    assert_eq!(trace[..3], [0, 1, 2], "{trace:?}");
    assert!(
        trace.windows(3).any(|w| w == [2, 1, 2] || w == [2, 1, 0]),
        "tracking lost and regained: {trace:?}"
    );
    assert!(trace.ends_with(&[2, 3, 4]), "{trace:?}");
    // 004 §1: "a final position within several inches of the dock".
    let off_in = off_mark_in(end);
    assert!(off_in < 6.0, "ends {off_in:.2} in from the mark");
    // Square to the dock: 004 gives no bound; sonar positioning holds the heading tracking left.
    assert!(harvey_geometry::wrap(end.heading_rad).to_degrees().abs() < 10.0, "{end:?}");
}
