//! Recognising a class I landmark (a vertical line: a door jamb, a corner) inside the window the
//! Expecter gave (002 §5.1, 001 §2: windowed, action-oriented perception): the one strong vertical
//! edge in the window is the landmark, and its column gives the bearing through the calibration.
//! No edge: "not found". Several edges of like strength: no answer (ambiguous), never a guess.
//! An edge's strength is its step measured across a few columns (`span_px`, so that an edge a
//! soft lens spreads over several columns counts whole) in bands of rows (`profile.rs`: noise
//! averages out over a band instead of adding a floor of its own), less what noise alone gives.
//! It must be a step, not a thin line, stand a few of its noise deviations clear (`z`) and pass
//! a threshold lowered in a dim window: the same edge counts in a dim frame, a vignetted corner
//! or under a passing cloud as in a bright one.

pub mod band;
pub mod ground;
pub mod point;
mod profile;

use harvey_msgs::{Expectation, FrameHeader, Header, LandmarkSighting, SightingKind};
use harvey_vision::image::{Gray, Rect};
use harvey_vision::noise::noise_sigma;

use profile::Profile;

/// Recognises class I landmarks; keeps its column profile between frames.
#[derive(Debug)]
pub struct LineLandmarks {
    /// Focal length in pixels at the frames' width.
    pub focal_px: f64,
    /// Mean step (grey levels) for an edge to count; lowered in proportion in a window darker
    /// than mid-grey (128).
    pub threshold: f32,
    /// The strongest edge must beat the second by this factor to be taken as the landmark.
    pub dominance: f32,
    /// Bearing error of a recognised edge, in pixels.
    pub sd_px: f64,
    /// Columns a step is measured across: 1 for a sharp lens; a lens that blurs over a radius
    /// of `r` pixels spreads an edge over `1 + 2 r` columns, which the step must take in whole
    /// (`with_blur`). No wider, or the edges of a sign beside a corner add to it.
    pub span_px: usize,
    /// Rows per band of the profile: 8 average a pixel's noise down almost threefold and keep
    /// a jamb's change of contrast at a lintel or a baseboard in bands of its own (of 4, 8 and
    /// 16, the fewest wrong answers in `tests/landmarks_light.rs`).
    pub band_rows: usize,
    /// An edge's strength must be this many of its noise deviations (the window's sensor
    /// noise averaged over a band, then over the bands) clear of zero.
    pub z: f32,
    /// An edge whose agreement with the predicted look (`Profile::agreement`, -1 to 1) is
    /// below the negative of this runs the other way from the landmark: never taken, and no
    /// rival where the look is clear (`clear_look`); under `faint_look` nothing is refused.
    pub contrary: f32,
    /// The least mean predicted step (reflectance, over the look's bands) for the look to be
    /// used: a tenth of the scale, 22 grey levels in full light, about the edge threshold.
    pub clear_look: f32,
    /// Below this mean predicted step there is no look to go by (a lamppost against the sky
    /// gives about 0; the Expecter zeroes the bands the map cannot tell): nothing is refused
    /// for its polarity. A fiftieth of the scale, 5 grey levels in full light.
    pub faint_look: f32,
    profile: Profile,
    peaks: Vec<(usize, f32)>,
    seq: u64,
}

impl LineLandmarks {
    /// How many messages it has numbered: kept across a restart (a checkpoint), so that a
    /// restarted worker numbers on.
    pub fn numbered(&self) -> u64 {
        self.seq
    }

    pub fn number_from(&mut self, seq: u64) {
        self.seq = seq;
    }

    /// Numbers a sighting another recogniser made (one numbering on `vision/sightings`).
    pub fn number(&mut self, s: &mut LandmarkSighting) {
        self.seq += 1;
        s.header.seq = self.seq;
    }

    pub fn new(focal_px: f64, threshold: f32) -> Self {
        Self {
            focal_px,
            threshold,
            dominance: 2.0,
            sd_px: 1.5,
            span_px: 1,
            band_rows: 8,
            z: 6.0,
            contrary: 0.5,
            clear_look: 0.1,
            faint_look: 0.02,
            profile: Profile::default(),
            peaks: Vec::new(),
            seq: 0,
        }
    }

    /// The same recogniser for a camera whose mount is calibrated to `calibration_sd_rad`: the
    /// bearing's spread takes that in (`[survey] calibration_sd_rad`).
    pub fn with_calibration_sd(self, calibration_sd_rad: f64) -> Self {
        let mount_px = self.focal_px * calibration_sd_rad;
        Self { sd_px: self.sd_px.hypot(mount_px), ..self }
    }

    /// The same recogniser for a lens of this blur radius (`[camera] blur_px`, the optics as
    /// calibrated): steps measured across the columns it spreads an edge over.
    pub fn with_blur(self, blur_px: u32) -> Self {
        Self { span_px: 1 + 2 * blur_px as usize, ..self }
    }

    /// Looks for the landmark of `e` (class 1) in a mono8 or rgb8 frame. `None`: not a class I
    /// expectation for this frame's size, a window off the frame, or an ambiguous window.
    pub fn recognise(&mut self, h: &FrameHeader, pixels: &[u8], e: &Expectation) -> Option<LandmarkSighting> {
        let bpp = h.encoding()?.bytes_per_pixel() as usize;
        let (w, ht, stride) = (h.width_px as usize, h.height_px as usize, h.stride_bytes as usize);
        if e.class != 1
            || (e.width_px, e.height_px) != (h.width_px, h.height_px)
            || stride < w * bpp
            || pixels.len() < stride * ht
        {
            return None;
        }
        let [u0, v0, u1, v1] = e.window_px.map(|x| x.max(0.0) as usize);
        let (u1, v1) = (u1.min(w), v1.min(ht));
        let span = self.span_px.max(1);
        if u1 < u0 + span + 2 || v1 <= v0 {
            return None;
        }
        let (mean, band_rows) = self.profile.fill(pixels, stride, bpp, [u0, v0, u1, v1], self.band_rows);
        // The window's sensor noise (`harvey_vision::noise`; 0 in a clean frame): a step between
        // two columns' means over a band deviates by `band_sd`; its magnitude's mean is the
        // floor noise alone gives, and the mean over the bands deviates by about `band_sd` over
        // the root of their number. Mono frames; colour ones count from 0.
        let sigma = if bpp == 1 {
            Gray::new(pixels, w, ht, stride).map_or(0.0, |g| noise_sigma(&g, Rect::new(u0, v0, u1, v1)))
        } else {
            0.0
        };
        let band_sd = sigma * std::f32::consts::SQRT_2 / band_rows.sqrt();
        let bands = ((v1 - v0) as f32 / band_rows).max(1.0);
        self.profile.strengths(span, band_sd * std::f32::consts::FRAC_2_SQRT_PI / std::f32::consts::SQRT_2);
        // Dim windows count weaker edges (the same contrast at less light); bright ones never
        // need more than the threshold.
        let noise = self.z * band_sd / bands.sqrt();
        let threshold = (self.threshold * (mean / 128.0).clamp(0.1, 1.0)).max(noise);
        // Every edge that could make the answer ambiguous, those under the threshold too.
        self.find_peaks((threshold / self.dominance).max(noise), span);
        // An edge stepping the other way from the look the map predicts, clearly, is another
        // edge (a look-alike: the next door's other jamb). Where the landmark's own step is
        // predicted clear, it is neither the landmark nor its rival; beside a faint landmark
        // it stays a rival (the landmark may be too faint to see, and the look-alike left the
        // only edge of the right polarity in the window) but is never taken. Under `faint_look`
        // there is no look to go by.
        let predicted = e.contrast.iter().map(|c| c.abs()).sum::<f32>() / e.contrast.len() as f32;
        let contrary = |profile: &Profile, k| profile.agreement(k, span, &e.contrast) < -self.contrary;
        if predicted >= self.clear_look {
            let profile = &self.profile;
            self.peaks.retain(|&(k, _)| !contrary(profile, k));
        }
        // Numbered only when sent, so that a gap in `seq` means a lost message.
        let header = Header::new(self.seq + 1, h.stamp_ns);
        let base = LandmarkSighting {
            header,
            frame_seq: h.seq,
            landmark_index: e.landmark_index,
            ..Default::default()
        };
        let best = self.peaks.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((k, strength)) = best.filter(|b| b.1 > threshold) else {
            self.seq += 1;
            return Some(LandmarkSighting { kind: SightingKind::NotFound as u32, ..base });
        };
        // Another edge of like strength, not the same one's plateau (a sharp edge is `span`
        // columns wide in the profile): ambiguous.
        if self.peaks.iter().any(|&(j, s)| j.abs_diff(k) > span && s * self.dominance > strength)
            || (predicted >= self.faint_look && contrary(&self.profile, k))
        {
            return None;
        }
        let u_edge = (u0 + 1) as f64 + self.profile.edge_at(k, span);
        let cx = w as f64 / 2.0;
        self.seq += 1;
        Some(LandmarkSighting {
            kind: SightingKind::Bearing as u32,
            a: ((cx - u_edge) / self.focal_px).atan(),
            a_sd: self.sd_px / self.focal_px,
            ..base
        })
    }

    /// The local maxima of the profile's strength over `floor` that are steps, not thin lines,
    /// as (column, strength).
    fn find_peaks(&mut self, floor: f32, span: usize) {
        let (p, profile) = (&self.profile.strength, &self.profile);
        self.peaks.clear();
        self.peaks.extend(
            (0..p.len())
                .filter(|&k| {
                    p[k] > floor
                        && (k == 0 || p[k] >= p[k - 1])
                        && (k + 1 == p.len() || p[k] > p[k + 1])
                        && profile.is_step(k, span)
                        && profile.coverage(k, span, (0.3 * p[k]).max(floor)) >= 0.5
                })
                .map(|k| (k, p[k])),
        );
    }
}

#[cfg(test)]
mod tests;
