//! The vision workers' request/result protocol (`vision/requests`, `vision/results`): a request
//! names the algorithm, its parameters and the image window (and, to correlate, the landmark
//! and the pose to expect it from); the result carries the frame's `seq` and stamp.

use crate::{Header, Message, Pose2, ZeroCopySend};

/// Most items one result carries.
pub const MAX_VISION_ITEMS: usize = 32;

/// What a request asks for (`VisionRequest::algorithm`). The parameters, in `params` order:
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum VisionAlgorithm {
    /// Reflectance-normalised correlation of the landmark's ray-traced appearance template
    /// (000 §5.3–5.4), centred on the landmark's point (class I: half-way up; else its
    /// position) moved by `params[2..5]` metres (x, y, z), to centre it on a vertex where
    /// reflectances meet (000 §5.2). params: template side (px, default 16), minimum score
    /// (default 0.9), dx, dy, dz. Item: `[u, v, score, expected_u, expected_v, 0]`, the point's
    /// image position found and expected.
    Correlate = 1,
    /// Moravec interest operator (001 §2.4). params: window (5), threshold (2000), suppression
    /// radius (3). Items: `[x, y, interest, 0, 0, 0]`, strongest first.
    Moravec = 2,
    /// Fast line finder (001 §2.1). params: buckets (8), offset (deg), minimum gradient (8),
    /// minimum length (10), orientation range lo, hi (deg; NaN: any). Items:
    /// `[x0, y0, x1, y1, mean_gradient, dispersion]`, longest first.
    LineFinder = 3,
    /// Fast region segmenter (001 §2.2). params: lo, hi (grey levels), minimum area (px).
    /// Items: `[cx, cy, area, mean, sd, 0]`, largest first.
    RegionSegmenter = 4,
    /// Phototropic perception (004 §4.1): the largest region within `params[0]` grey levels
    /// (default 20) of the brightest pixel, of at least `params[1]` pixels (default 20).
    /// Item: `[cx, cy, area, mean, median, 0]`, `median` the window's median grey level (what
    /// the region's brightness is judged against).
    Phototropic = 5,
    /// Activity detection (004 §4.1), best as a standing request: the motion over the last
    /// `params[2]` frames (default 4) of the window (which must keep its size), each frame
    /// pair's absolute difference (`params[0]` = 0) or one vote per difference over
    /// `params[1]` (`params[0]` = 1, default threshold 20). Item: `[cx, cy, strength, 0, 0, 0]`,
    /// from the second frame on.
    Activity = 6,
    /// The constrained Hough transform's dock recognition (004 §4.1.2): fast-line-finder lines
    /// of the window vote for the 2 x 1 frame-with-post model (`DockModel::frame_with_post`,
    /// half a model unit a side) under `params[2]` scale hypotheses (default 5) spread evenly
    /// from `params[0]` to `params[1]` pixels per model unit (the range the requester's spatial
    /// uncertainty allows), image rotation `params[3]` (radians). A match covering less than
    /// `params[4]` of the model (default 0.5) is not found. Item: `[u, v, certainty, scale,
    /// left, right]`: the model's reference point (the frame's centre), the winning scale, and
    /// the apparent heights of its end posts (pixels, 0 where not seen; `hough::post_heights`).
    Dock = 7,
    /// Coded pole recognition (004 §5.1.1): the bright rings of the world's `[poles]` (grey
    /// levels from `params[0]`, default 200; at least `params[1]` pixels, default 3), grouped
    /// by column into poles of three rings. The top and bottom rings' spacing gives the range,
    /// the middle ring's height between them the code. Items, nearest first: `[u, range_m, code,
    /// v_top, v_bottom, 0]`. A world without `[poles]` is a bad parameter.
    Poles = 8,
    /// Stereo visual odometry stop to stop (003), on a stereo frame ([`crate::FrameHeader::views`]
    /// 2), best as a standing request whose id keeps its features: `expected` is the motion
    /// predicted since the last answered frame (x, y in metres, heading in radians, in that stop's
    /// robot frame). params: start afresh at this frame (1) or not (0; the first frame of an id
    /// starts), solver (0 match-then-solve, 1 Lucas registration), the prediction's standard
    /// deviations x, y (m), heading (rad) (zeros: the worker's `--odometry` settings). The
    /// window is not used. Items: `[dx, dy, dheading, sd_x, sd_y, sd_heading]` the motion
    /// (zeros unless solved), `[features, used, carried, reacquired, pruned, error_scale]`,
    /// then obstacle points `[x, y, z, range_sd, u, v]` in this stop's robot frame (features
    /// that held since the last stop: none at a start), nearest first. `NotFound`: no motion solution (too few features held; the next frame is solved
    /// against this one). A mono frame is a bad frame; a world without a stereo baseline or a
    /// worker without settings, a bad parameter.
    StereoOdometry = 9,
    /// Path following with the line finder (001 §2.1), best as a standing request: the line
    /// finder's fragments in the window (below the horizon) grouped into the path's two edges
    /// near their predicted places, the edges giving the centreline; each confident fit predicts
    /// the next frame's edges (feed-forward), and where the fit falls short the tolerances are
    /// widened once. The first request of an id, or one whose parameters differ from the last,
    /// starts the tracking afresh from its edges. `expected`: `x_m` and `y_m` are the two image
    /// rows the predicted edges are given at (the window may change under a standing request; the
    /// tracking goes on in it). params: the left edge's column at those two rows, the right
    /// edge's likewise, the grouping's distance (px, default 30)
    /// and angle (degrees, default 10), the least total fragment length of a fit (px, default
    /// 60), and a free number (a new value starts the tracking afresh from the same edges). Items: `[vanishing_u, vanishing_v, bottom_u, bottom_v, confidence, 0]` the
    /// centreline through the edges' vanishing point and the middle of the path at the window's
    /// bottom row, then each edge (left, right) `[u, v, angle, 0, 0, 0]` (a point and the
    /// direction in radians). `NotFound`: no confident fit (the prediction is kept).
    Path = 10,
    /// Depth from motion and obstacle extraction (001 §2.3, Table 1), as a sequence of one-off
    /// requests of one id, one per frame of a straight run: the first (travel 0, or any whose
    /// parameters differ from the last) starts afresh with the Moravec points of the window;
    /// each later one tracks them along their radial lines from the focus of expansion (the
    /// image's centre: the camera translates along its axis) and refits each point's depth.
    /// `expected`: `x_m` the travel along the axis since the first frame (m, from the
    /// odometry; it must grow), `heading_rad` the camera's turn since then (rad, left positive):
    /// the worker registers the frame within 10 px of the last frame's shift moved on by that
    /// turn's. params: a free number (a new value starts afresh), the least correlation score
    /// of a match (default 0.9), the Moravec threshold (3000), most points (60), the position
    /// noise (px, 0.5), the least height above the floor of an obstacle (m, 0.1; by the world's
    /// camera height), unused, and the largest relative spread of a depth judged (0.1). Items:
    /// `[shift_u, shift_v, tracked, with_depth, number, travel_m]`, the shift this frame was
    /// registered by against the first (px; the camera's true turn since then is `atan(shift_u
    /// / f)`, a visual compass), the counts of points (zeros but `tracked` at the first frame)
    /// and the request's free number and travel echoed; then each point with a depth, those
    /// standing off the floor first, each kind nearest first: `[u, v, depth_m, sd_m, frames,
    /// class]`, `u, v` where it is in this frame, `class` 1 standing off the floor, 0 on it, -1
    /// not judged. `NotFound`: a later frame of a run the worker does not hold (it restarted).
    Depth = 11,
}

impl VisionAlgorithm {
    pub fn from_raw(raw: u32) -> Option<Self> {
        use VisionAlgorithm::*;
        [
            Correlate,
            Moravec,
            LineFinder,
            RegionSegmenter,
            Phototropic,
            Activity,
            Dock,
            Poles,
            StereoOdometry,
            Path,
            Depth,
        ]
        .into_iter()
        .find(|a| *a as u32 == raw)
    }
}

/// How a request went (`VisionResult::status`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum VisionStatus {
    Found = 0,
    NotFound = 1,
    WindowOutsideFrame = 2,
    UnknownLandmark = 3,
    UnknownAlgorithm = 4,
    BadParameter = 5,
    /// The template is empty, too large, or leaves the image.
    BadTemplate = 6,
    /// The frame cannot be read (encoding, size).
    BadFrame = 7,
}

impl VisionStatus {
    pub fn from_raw(raw: u32) -> Option<Self> {
        use VisionStatus::*;
        [
            Found,
            NotFound,
            WindowOutsideFrame,
            UnknownLandmark,
            UnknownAlgorithm,
            BadParameter,
            BadTemplate,
            BadFrame,
        ]
        .into_iter()
        .find(|s| *s as u32 == raw)
    }
}

/// A request to the vision workers.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend, serde::Serialize, serde::Deserialize)]
#[repr(C)]
#[type_name("harvey_msgs/VisionRequest")]
pub struct VisionRequest {
    pub header: Header,
    /// Chosen by the requester; results echo it. Workers sharing the load split by it.
    pub request_id: u32,
    /// [`VisionAlgorithm`] as its discriminant.
    pub algorithm: u32,
    /// 1: answer on every frame until a request with the same id replaces it; 0: the next frame.
    pub standing: u32,
    /// Index of the landmark in the world file (correlation).
    pub landmark_index: u32,
    /// The pose to build the template from (correlation).
    pub expected: Pose2,
    /// `[u0, v0, u1, v1]` in pixels; all zero: the whole frame.
    pub window_px: [f32; 4],
    pub params: [f32; 8],
}
crate::payloads::message!(VisionRequest);

impl VisionRequest {
    /// A one-off [`VisionAlgorithm::Correlate`] request over the whole frame: landmark
    /// `landmark_index`'s point moved by `offset_m`, its template `template_px` square, ray-traced
    /// from `expected`; found when it scores `min_score`.
    pub fn correlate(
        request_id: u32,
        stamp_ns: u64,
        landmark_index: u32,
        expected: Pose2,
        offset_m: [f64; 3],
        template_px: u32,
        min_score: f64,
    ) -> Self {
        let o = offset_m.map(|v| v as f32);
        Self {
            header: Header::new(u64::from(request_id), stamp_ns),
            request_id,
            algorithm: VisionAlgorithm::Correlate as u32,
            standing: 0,
            landmark_index,
            expected,
            window_px: [0.0; 4],
            params: [template_px as f32, min_score as f32, o[0], o[1], o[2], 0.0, 0.0, 0.0],
        }
    }
}

/// One found thing; the algorithm says what the six numbers are.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/VisionItem")]
pub struct VisionItem {
    pub values: [f32; 6],
}

/// A worker's answer to one request on one frame.
#[derive(Debug, Default, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/VisionResult")]
pub struct VisionResult {
    /// `stamp_ns` is the frame's.
    pub header: Header,
    pub frame_seq: u64,
    pub request_id: u32,
    pub algorithm: u32,
    /// [`VisionStatus`] as its discriminant.
    pub status: u32,
    /// Items found in all (`items` holds the first [`MAX_VISION_ITEMS`]).
    pub found: u32,
    pub count: u32,
    pub reserved: u32,
    pub items: [VisionItem; MAX_VISION_ITEMS],
}
crate::payloads::message!(VisionResult);
