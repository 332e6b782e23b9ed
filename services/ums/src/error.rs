//! Why the UMS refused an input: one typed error per kind of input (odometry, a landmark
//! sighting, a pose fix). A refused input leaves the map as it was.

use crate::reduction::Rejection;

/// Why an odometry message was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OdometryError {
    #[error("odometry at {stamp_ns} ns is older than the last ({last_ns} ns)")]
    OutOfOrder { stamp_ns: u64, last_ns: u64 },
    #[error("odometry holds a non-finite number")]
    NotFinite,
}

/// Why a landmark sighting was refused, when it came or when it fell due.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SightingError {
    #[error("sighting of landmark #{index} which is not in the world")]
    UnknownLandmark { index: u32 },
    #[error("sighting of `{landmark}` has unknown kind {kind}")]
    UnknownKind { landmark: String, kind: u32 },
    #[error("sighting of `{landmark}` holds a non-finite number")]
    NotFinite { landmark: String },
    /// Stamped before the oldest map the UMS still keeps.
    #[error("sighting of `{landmark}` at {stamp_ns} ns is older than the map's history: stamps out of order")]
    TooOld { landmark: String, stamp_ns: u64 },
    /// The reduction found no pose in the map consistent with it.
    #[error("sighting of `{landmark}`: {why}")]
    Rejected { landmark: String, why: Rejection },
}

/// Why a pose fix was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FixError {
    #[error("pose fix at {stamp_ns} ns holds a non-finite number")]
    NotFinite { stamp_ns: u64 },
    /// Stamped before the oldest map the UMS still keeps.
    #[error("pose fix at {stamp_ns} ns is older than the map's history: stamps out of order")]
    TooOld { stamp_ns: u64 },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reasons_read_as_the_logs_have_always_shown_them() {
        let old = OdometryError::OutOfOrder { stamp_ns: 10, last_ns: 250 };
        assert_eq!(old.to_string(), "odometry at 10 ns is older than the last (250 ns)");
        let late = SightingError::TooOld { landmark: "office-sign".into(), stamp_ns: 10 };
        assert_eq!(
            late.to_string(),
            "sighting of `office-sign` at 10 ns is older than the map's history: stamps out of order"
        );
        let none = SightingError::Rejected { landmark: "office-sign".into(), why: Rejection::NoHeading };
        assert_eq!(
            none.to_string(),
            "sighting of `office-sign`: no heading in the wedge is consistent with the sighting"
        );
        assert_eq!(
            FixError::TooOld { stamp_ns: 7 }.to_string(),
            "pose fix at 7 ns is older than the map's history: stamps out of order"
        );
    }
}
