//! Answers vision requests on a frame read in place: runs the requested kernel inside the
//! requested window and packs what it found into a `VisionResult` carrying the frame's `seq`
//! and stamp. A bad request gets an error status, never a panic. The answer depends only on
//! the frame and the request, so any worker gives the same one; buffers are kept between frames.

use harvey_msgs::{
    Encoding, FrameHeader, Header, MAX_VISION_ITEMS, VisionAlgorithm, VisionItem, VisionRequest,
    VisionResult, VisionStatus,
};
use harvey_vision::cues::{ActivityDetector, ActivityVote, brightest};
use harvey_vision::flf::{Flf, FlfParams};
use harvey_vision::frs::{ClassRange, Frs};
use harvey_vision::hough::{DockModel, HoughScratch, Hypothesis, find_dock, post_heights};
use harvey_vision::levels;
use harvey_vision::moravec::{Moravec, MoravecParams};
use harvey_vision::nc::{Correlator, Template};
use harvey_vision::{Gray, GrayBuf, Rect, VisionError};
use harvey_world::World;

use crate::depth::DepthTrackers;
use crate::odometry::{Odometries, Outcome};
use crate::odometry_config::OdometryConfig;
use crate::path::PathTrackers;
use crate::templates::{AppearanceTemplate, build_into};

/// A worker's kernels and their buffers.
pub struct Dispatcher {
    world: World,
    grey: Vec<u8>,
    correlator: Correlator,
    template: AppearanceTemplate,
    prepared: Option<Template>,
    moravec: Moravec,
    flf: Flf,
    frs: Frs,
    /// Activity detection keeps frames: one detector per (standing) request.
    activity: std::collections::BTreeMap<u32, ActivityDetector>,
    dock_model: DockModel,
    hypotheses: Vec<Hypothesis>,
    dock_scratch: HoughScratch,
    poles: Vec<[f32; 6]>,
    odometries: Odometries,
    /// Path following keeps a tracker per (standing) request.
    paths: PathTrackers,
    /// Depth from motion likewise.
    depths: DepthTrackers,
    seq: u64,
}

pub(crate) fn status_of(e: &VisionError) -> VisionStatus {
    match e {
        VisionError::WindowOutside(..) => VisionStatus::WindowOutsideFrame,
        VisionError::EmptyTemplate | VisionError::TemplateTooLarge(..) => VisionStatus::BadTemplate,
        VisionError::BadImage { .. } => VisionStatus::BadFrame,
        VisionError::BadParameter(_) => VisionStatus::BadParameter,
    }
}

/// `params[i]`, or `default` when it is zero (unset).
fn param(r: &VisionRequest, i: usize, default: f32) -> f32 {
    if r.params[i] == 0.0 { default } else { r.params[i] }
}

impl Dispatcher {
    /// How many messages it has numbered: kept across a restart (a checkpoint), so that a
    /// restarted worker numbers on.
    pub fn numbered(&self) -> u64 {
        self.seq
    }

    pub fn number_from(&mut self, seq: u64) {
        self.seq = seq;
    }

    /// Stereo odometry requests are answered with `odometry`'s settings (without: refused as a
    /// bad parameter).
    pub fn with_odometry(mut self, odometry: Option<OdometryConfig>) -> Self {
        self.odometries = Odometries::new(odometry);
        self
    }

    pub fn new(world: World) -> Self {
        Self {
            world,
            grey: Vec::new(),
            correlator: Correlator::default(),
            template: AppearanceTemplate {
                pixels: GrayBuf::default(),
                origin: [0, 0],
                projection: [0.0, 0.0],
            },
            prepared: None,
            moravec: Moravec::default(),
            flf: Flf::default(),
            frs: Frs::default(),
            activity: std::collections::BTreeMap::new(),
            dock_model: DockModel::frame_with_post(),
            hypotheses: Vec::new(),
            dock_scratch: HoughScratch::default(),
            poles: Vec::new(),
            odometries: Odometries::default(),
            paths: PathTrackers::default(),
            depths: DepthTrackers::default(),
            seq: 0,
        }
    }

    /// The answer to `req` on the frame `h`/`pixels`.
    pub fn answer(&mut self, h: &FrameHeader, pixels: &[u8], req: &VisionRequest) -> VisionResult {
        self.seq += 1;
        let mut out = VisionResult {
            header: Header::new(self.seq, h.stamp_ns),
            frame_seq: h.seq,
            request_id: req.request_id,
            algorithm: req.algorithm,
            ..Default::default()
        };
        // `Ok(true)`: items that say why nothing was found (a stereo odometry without a motion).
        let status = match self.run(h, pixels, req, &mut out) {
            Ok(unsolved) if out.found == 0 || unsolved => VisionStatus::NotFound,
            Ok(_) => VisionStatus::Found,
            Err(s) => s,
        };
        out.status = status as u32;
        out
    }

    fn run(
        &mut self,
        h: &FrameHeader,
        pixels: &[u8],
        req: &VisionRequest,
        out: &mut VisionResult,
    ) -> Result<bool, VisionStatus> {
        let algorithm = VisionAlgorithm::from_raw(req.algorithm).ok_or(VisionStatus::UnknownAlgorithm)?;
        let (w, ht) = (h.width_px as usize, h.height_px as usize);
        let img = match h.encoding() {
            Some(Encoding::Mono8) => Gray::new(pixels, w, ht, h.stride_bytes as usize),
            Some(Encoding::Rgb8) => {
                // Luma of each pixel into a kept buffer (BT.601 weights, integer).
                let stride = h.stride_bytes as usize;
                if pixels.len() < stride * ht || stride < 3 * w {
                    return Err(VisionStatus::BadFrame);
                }
                self.grey.clear();
                for y in 0..ht {
                    let row = &pixels[y * stride..y * stride + 3 * w];
                    self.grey.extend(row.chunks_exact(3).map(|p| {
                        ((77 * u32::from(p[0]) + 150 * u32::from(p[1]) + 29 * u32::from(p[2])) >> 8) as u8
                    }));
                }
                Gray::new(&self.grey, w, ht, w)
            }
            None => return Err(VisionStatus::BadFrame),
        }
        .map_err(|e| status_of(&e))?;
        let window = window_of(req, w, ht)?;
        let mut push = |values: [f32; 6]| push_item(out, values);
        match algorithm {
            VisionAlgorithm::Moravec => {
                let p = MoravecParams {
                    window: param(req, 0, 5.0) as usize,
                    threshold: param(req, 1, 2000.0) as u32,
                    suppress_radius: param(req, 2, 3.0) as usize,
                    max_corners: MAX_VISION_ITEMS,
                };
                for c in self.moravec.corners(&img, window, &p).map_err(|e| status_of(&e))? {
                    push([c.x as f32 + 0.5, c.y as f32 + 0.5, c.interest as f32, 0.0, 0.0, 0.0]);
                }
            }
            VisionAlgorithm::LineFinder => {
                let (lo, hi) = (req.params[4], req.params[5]);
                let p = FlfParams {
                    buckets: param(req, 0, 8.0) as u8,
                    offset_deg: req.params[1],
                    min_gradient: param(req, 2, 8.0),
                    min_length: param(req, 3, 10.0),
                    orientation_deg: (lo.is_finite() && hi.is_finite() && (lo, hi) != (0.0, 0.0))
                        .then_some((lo, hi)),
                    ..FlfParams::default()
                };
                for l in self.flf.lines(&img, window, &p).map_err(|e| status_of(&e))? {
                    push([l.from[0], l.from[1], l.to[0], l.to[1], l.mean_gradient, l.dispersion]);
                }
            }
            VisionAlgorithm::RegionSegmenter => {
                let (lo, hi) = (req.params[0], req.params[1]);
                if !(0.0..=255.0).contains(&lo) || !(lo..=255.0).contains(&hi) {
                    return Err(VisionStatus::BadParameter);
                }
                let ranges = [ClassRange { lo: lo as u8, hi: hi as u8, class: 1 }];
                let regions = self.frs.segment(&img, window, &ranges, param(req, 2, 20.0) as u32);
                for r in regions.map_err(|e| status_of(&e))? {
                    push([r.centroid[0], r.centroid[1], r.area as f32, r.mean, r.sd, 0.0]);
                }
            }
            VisionAlgorithm::Phototropic => {
                let (margin, area) = (param(req, 0, 20.0), param(req, 1, 20.0));
                if !(0.0..=255.0).contains(&margin) || area < 1.0 {
                    return Err(VisionStatus::BadParameter);
                }
                let found = brightest(&mut self.frs, &img, window, margin as u8, area as u32)
                    .map_err(|e| status_of(&e))?;
                if let Some(r) = found {
                    let median = levels::percentile(&levels::histogram(&img, window), 0.5);
                    push([r.centroid[0], r.centroid[1], r.area as f32, r.mean, f32::from(median), 0.0]);
                }
            }
            VisionAlgorithm::Dock => {
                let (lo, hi, n) = (req.params[0], req.params[1], param(req, 2, 5.0));
                let (rotation, min_certainty) = (req.params[3], param(req, 4, 0.5));
                let sane = lo.is_finite() && lo >= 2.0 && hi >= lo && hi < 1000.0 && rotation.is_finite();
                if !sane || !(1.0..=16.0).contains(&n) || !(0.0..=1.0).contains(&min_certainty) {
                    return Err(VisionStatus::BadParameter);
                }
                let n = n as usize;
                self.hypotheses.clear();
                self.hypotheses.extend((0..n).map(|k| Hypothesis {
                    scale: if n == 1 { lo } else { lo + (hi - lo) * k as f32 / (n - 1) as f32 },
                    rotation,
                }));
                let p = FlfParams { min_length: 6.0, ..FlfParams::default() };
                let lines = self.flf.lines(&img, window, &p).map_err(|e| status_of(&e))?;
                let found = find_dock(
                    lines,
                    &self.dock_model,
                    &self.hypotheses,
                    [w, ht],
                    4.0,
                    &mut self.dock_scratch,
                );
                if let Some(m) = found.filter(|m| m.certainty >= min_certainty) {
                    let [left, right] = post_heights(lines, m.at, m.scale);
                    push([m.at[0], m.at[1], m.certainty, m.scale, left, right]);
                }
            }
            VisionAlgorithm::Poles => {
                let field = self.world.poles.as_ref().ok_or(VisionStatus::BadParameter)?;
                // A grey level given (params[0]) is used as it is; else the threshold follows the
                // window's brightness, `contrast` (params[2]) times its bright background.
                let (area, contrast) = (param(req, 1, 3.0), param(req, 2, crate::poles::RING_CONTRAST));
                if !(1.0..=4.0).contains(&contrast) || area < 1.0 {
                    return Err(VisionStatus::BadParameter);
                }
                let lo = match req.params[0] {
                    0.0 => f32::from(crate::poles::ring_threshold(&img, window, contrast)),
                    lo => lo,
                };
                if !(1.0..=255.0).contains(&lo) {
                    return Err(VisionStatus::BadParameter);
                }
                let ranges = [ClassRange { lo: lo as u8, hi: 255, class: 1 }];
                let rings =
                    self.frs.segment(&img, window, &ranges, area as u32).map_err(|e| status_of(&e))?;
                let focal = self.world.camera.focal_for(w as u32);
                self.poles.clear();
                let farthest = self.world.diagonal_m();
                for pole in crate::poles::group(rings, field, focal, w as u32, farthest) {
                    self.poles.push(pole);
                }
                self.poles.sort_by(|a, b| a[1].total_cmp(&b[1]));
                for p in &self.poles {
                    push(*p);
                }
            }
            VisionAlgorithm::Activity => {
                let vote = match req.params[0] {
                    0.0 => ActivityVote::Difference,
                    1.0 => ActivityVote::Threshold(param(req, 1, 20.0).clamp(0.0, 255.0) as u8),
                    _ => return Err(VisionStatus::BadParameter),
                };
                let depth = param(req, 2, 4.0) as usize;
                let detector =
                    self.activity.entry(req.request_id).or_insert_with(|| ActivityDetector::new(vote, depth));
                if detector.vote != vote {
                    *detector = ActivityDetector::new(vote, depth);
                }
                if let Some(a) = detector.push(&img, window).map_err(|e| status_of(&e))?
                    && a.strength > 0.0
                {
                    push([a.centroid[0], a.centroid[1], a.strength, 0.0, 0.0, 0.0]);
                }
            }
            VisionAlgorithm::Path => self.paths.answer(&mut self.flf, &img, window, req, &mut push)?,
            VisionAlgorithm::Depth => {
                let camera = (self.world.camera.focal_for(w as u32), self.world.camera.height_m);
                self.depths.answer(&img, window, camera, req, &mut push)?;
            }
            VisionAlgorithm::StereoOdometry => {
                let outcome = self.odometries.answer(&self.world, h, pixels, req, &mut push)?;
                return Ok(outcome == Outcome::NoSolution);
            }
            VisionAlgorithm::Correlate => {
                let l = self
                    .world
                    .landmarks
                    .get(req.landmark_index as usize)
                    .ok_or(VisionStatus::UnknownLandmark)?;
                let base = l.point();
                let point = [0, 1, 2].map(|k| base[k] + f64::from(req.params[2 + k]));
                let side = param(req, 0, 16.0) as usize;
                let pose = req.expected;
                if !build_into(&mut self.template, &self.world, pose, point, [h.width_px, h.height_px], side)
                {
                    return Err(VisionStatus::BadTemplate);
                }
                match &mut self.prepared {
                    Some(t) => t.set(&self.template.pixels),
                    None => Template::new(&self.template.pixels).map(|t| self.prepared = Some(t)),
                }
                .map_err(|e| status_of(&e))?;
                let t = self.prepared.as_ref().ok_or(VisionStatus::BadTemplate)?;
                let m = self.correlator.best(&img, window, t).map_err(|e| status_of(&e))?;
                // The landmark point sits where it sat in the template.
                let [pu, pv] = self.template.projection;
                let (ox, oy) = (self.template.origin[0] as f32, self.template.origin[1] as f32);
                let found = [
                    m.centre[0] - t.width as f32 / 2.0 + (pu as f32 - ox),
                    m.centre[1] - t.height as f32 / 2.0 + (pv as f32 - oy),
                ];
                if m.score >= param(req, 1, 0.9) {
                    push([found[0], found[1], m.score, pu as f32, pv as f32, 0.0]);
                }
            }
        }
        Ok(false)
    }
}

/// Adds an item to `out` (counted in `found` when there is no room left).
fn push_item(out: &mut VisionResult, values: [f32; 6]) {
    if (out.count as usize) < MAX_VISION_ITEMS {
        out.items[out.count as usize] = VisionItem { values };
        out.count += 1;
    }
    out.found += 1;
}

/// The request's window: all zeros for the whole frame; one that leaves the frame is an error.
fn window_of(req: &VisionRequest, w: usize, h: usize) -> Result<Rect, VisionStatus> {
    let [u0, v0, u1, v1] = req.window_px;
    if [u0, v0, u1, v1] == [0.0; 4] {
        return Ok(Rect::new(0, 0, w, h));
    }
    let inside = |lo: f32, hi: f32, max: usize| {
        lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi <= max as f32 && lo < hi
    };
    if !inside(u0, u1, w) || !inside(v0, v1, h) {
        return Err(VisionStatus::WindowOutsideFrame);
    }
    Ok(Rect::new(u0.floor() as usize, v0.floor() as usize, u1.ceil() as usize, v1.ceil() as usize))
}
