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
    /// rival where the look is clear (`clear_look`).
    pub contrary: f32,
    /// The least mean predicted step (reflectance, over the look's bands) for the look to be
    /// used: a tenth of the scale, 22 grey levels in full light, about the edge threshold.
    pub clear_look: f32,
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
        // only edge of the right polarity in the window) but is never taken.
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
            || (predicted > 0.0 && contrary(&self.profile, k))
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
mod tests {
    use super::*;
    use harvey_msgs::Encoding;

    fn frame(edges: &[(u32, u8)]) -> Vec<u8> {
        (0..64 * 48)
            .map(|i| {
                let u = i % 64;
                edges.iter().rev().find(|(at, _)| u >= *at).map_or(50, |(_, v)| *v)
            })
            .collect()
    }

    fn expect(u0: f32, u1: f32) -> Expectation {
        Expectation {
            landmark_index: 4,
            class: 1,
            window_px: [u0, 10.0, u1, 40.0],
            width_px: 64,
            height_px: 48,
            ..Default::default()
        }
    }

    #[test]
    fn one_edge_in_the_window_gives_its_bearing() {
        let h = FrameHeader::new(9, 123, 64, 48, Encoding::Mono8);
        let mut r = LineLandmarks::new(55.4, 10.0);
        let s = r.recognise(&h, &frame(&[(40, 200)]), &expect(30.0, 50.0)).expect("an answer");
        assert_eq!(
            (s.kind, s.landmark_index, s.frame_seq, s.header.stamp_ns),
            (SightingKind::Bearing as u32, 4, 9, 123)
        );
        assert!((s.a - ((32.0 - 40.0) / 55.4f64).atan()).abs() < 1e-12, "{}", s.a);
    }

    #[test]
    fn no_edge_is_not_found_and_two_like_edges_are_no_answer() {
        let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
        let mut r = LineLandmarks::new(55.4, 10.0);
        let none = r.recognise(&h, &frame(&[(40, 200)]), &expect(5.0, 30.0)).expect("an answer");
        assert_eq!(none.kind, SightingKind::NotFound as u32);
        assert!(r.recognise(&h, &frame(&[(35, 150), (45, 250)]), &expect(30.0, 50.0)).is_none(), "ambiguous");
        // A dominant edge beside a weak one is still recognised.
        let s = r.recognise(&h, &frame(&[(35, 65), (45, 250)]), &expect(30.0, 50.0)).expect("dominant");
        assert_eq!(s.kind, SightingKind::Bearing as u32);
        let other_size = Expectation { width_px: 640, ..expect(30.0, 50.0) };
        assert!(r.recognise(&h, &frame(&[]), &other_size).is_none());
    }

    #[test]
    fn the_predicted_look_tells_the_landmark_from_a_look_alike_stepping_the_other_way() {
        // A bright door between columns 35 and 45: its two jambs step opposite ways, alike in
        // strength, so without a prediction the window is ambiguous.
        let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
        let f = frame(&[(35, 200), (45, 50)]);
        let mut r = LineLandmarks::new(55.4, 10.0);
        assert!(r.recognise(&h, &f, &expect(25.0, 55.0)).is_none(), "ambiguous");
        for (contrast, column) in [(0.4, 35.0), (-0.4, 45.0)] {
            let e = Expectation { contrast: [contrast; 4], ..expect(25.0, 55.0) };
            let s = r.recognise(&h, &f, &e).expect("an answer");
            assert_eq!(s.kind, SightingKind::Bearing as u32);
            assert!((s.a - bearing(column)).abs() < 1e-9, "{contrast}: {} for {column}", s.a);
        }
        // Only the look-alike in the window: not found, never taken for the landmark.
        let e = Expectation { contrast: [0.4; 4], ..expect(40.0, 55.0) };
        assert_eq!(r.recognise(&h, &f, &e).expect("an answer").kind, SightingKind::NotFound as u32);
    }

    #[test]
    fn a_frame_whose_rows_do_not_fit_its_stride_is_no_answer_not_a_panic() {
        let mut r = LineLandmarks::new(55.4, 10.0);
        let f = frame(&[(40, 200)]);
        for stride in [0, 1, 63] {
            let h = FrameHeader { stride_bytes: stride, ..FrameHeader::new(1, 0, 64, 48, Encoding::Mono8) };
            assert!(r.recognise(&h, &f, &expect(30.0, 50.0)).is_none(), "stride {stride}");
        }
        // An rgb8 header over mono bytes: three bytes a pixel do not fit a 64-byte row.
        let rgb = FrameHeader { stride_bytes: 64, ..FrameHeader::new(1, 0, 64, 48, Encoding::Rgb8) };
        assert!(r.recognise(&rgb, &f, &expect(30.0, 50.0)).is_none());
    }

    /// `frame` with seeded noise of deviation `sd` added.
    fn noisy(mut f: Vec<u8>, sd: f64, mut state: u64) -> Vec<u8> {
        for p in &mut f {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let n = ((state & 0xff) as f64 + ((state >> 8) & 0xff) as f64) / 255.0 - 1.0; // sd 0.41
            *p = (f64::from(*p) + n * sd / 0.41).round().clamp(0.0, 255.0) as u8;
        }
        f
    }

    /// The bearing of the boundary at column `u` of the test frames.
    fn bearing(u: f64) -> f64 {
        ((32.0 - u) / 55.4f64).atan()
    }

    #[test]
    fn a_dim_noisy_edge_is_found_where_it_is() {
        // A 25-level step at column 40 of a dim frame (grey 60 to 85) under noise of sd 8:
        // the old mean absolute difference had a noise floor of 9 levels everywhere.
        let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
        let f = noisy(frame(&[(0, 60), (40, 85)]), 8.0, 0x2545_f491_4f6c_dd1d);
        let mut r = LineLandmarks::new(55.4, 12.0);
        let s = r.recognise(&h, &f, &expect(30.0, 50.0)).expect("an answer");
        assert_eq!(s.kind, SightingKind::Bearing as u32, "found, not ambiguous");
        assert!((s.a - bearing(40.0)).abs() < 0.25 / 55.4, "within a quarter pixel: {}", s.a);
    }

    #[test]
    fn a_soft_noisy_edge_counts_whole() {
        // The harsh condition's end-wall corner: a 36-level step spread over three columns by
        // the lens (12 a column), noise of sd 8. Column by column, no step stands out of the
        // noise's mean absolute difference (9 levels); across three columns it is whole.
        let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
        for seed in [1u64, 2, 3, 4, 5] {
            let f = noisy(frame(&[(0, 100), (39, 112), (40, 124), (41, 136)]), 8.0, 0x9e37_79b9 * seed);
            let mut r = LineLandmarks::new(55.4, 12.0).with_blur(1);
            let s = r.recognise(&h, &f, &expect(25.0, 55.0)).expect("an answer");
            assert_eq!(s.kind, SightingKind::Bearing as u32, "seed {seed}");
            // The ramp's middle step is the boundary at 40.
            assert!((s.a - bearing(40.0)).abs() < 0.5 / 55.4, "seed {seed}: within half a pixel: {}", s.a);
        }
    }

    #[test]
    fn noise_alone_is_not_an_edge_however_low_the_threshold() {
        let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
        for seed in [1u64, 2, 3, 4, 5, 6, 7, 8] {
            let f = noisy(frame(&[(0, 120)]), 8.0, 0x51_7cc1_b727 * seed);
            let mut r = LineLandmarks::new(55.4, 0.5);
            let s = r.recognise(&h, &f, &expect(5.0, 60.0)).expect("an answer");
            assert_eq!(s.kind, SightingKind::NotFound as u32, "seed {seed}");
        }
    }
}
