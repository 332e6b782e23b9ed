//! Recognising a class I landmark (a vertical line: a door jamb, a corner) inside the window the
//! Expecter gave (002 §5.1, 001 §2: windowed, action-oriented perception): the one strong vertical
//! edge in the window is the landmark, and its column gives the bearing through the calibration.
//! No edge: "not found". Several edges of like strength: no answer (ambiguous), never a guess.
//! An edge's strength is the mean absolute step across it over the window's rows above the
//! window's own floor (the mean difference its estimated sensor noise alone gives), against a
//! threshold lowered in a dim window: the same edge counts in a dim frame, a vignetted corner or under a
//! passing cloud as in a bright one.

use harvey_msgs::{Expectation, FrameHeader, Header, LandmarkSighting, SightingKind};
use harvey_vision::image::{Gray, Rect};
use harvey_vision::noise::noise_sigma;

/// Recognises class I landmarks; keeps its column profile between frames.
#[derive(Debug)]
pub struct LineLandmarks {
    /// Focal length in pixels at the frames' width.
    pub focal_px: f64,
    /// Mean step (grey levels) above the window's floor for an edge to count; lowered in
    /// proportion in a window darker than mid-grey (128).
    pub threshold: f32,
    /// The strongest edge must beat the second by this factor to be taken as the landmark.
    pub dominance: f32,
    /// Bearing error of a recognised edge, in pixels.
    pub sd_px: f64,
    profile: Vec<f32>,
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

    pub fn new(focal_px: f64, threshold: f32) -> Self {
        Self {
            focal_px,
            threshold,
            dominance: 2.0,
            sd_px: 1.5,
            profile: Vec::new(),
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

    /// Looks for the landmark of `e` (class 1) in a mono8 or rgb8 frame. `None`: not a class I
    /// expectation for this frame's size, a window off the frame, or an ambiguous window.
    pub fn recognise(&mut self, h: &FrameHeader, pixels: &[u8], e: &Expectation) -> Option<LandmarkSighting> {
        let bpp = h.encoding()?.bytes_per_pixel() as usize;
        let (w, ht, stride) = (h.width_px as usize, h.height_px as usize, h.stride_bytes as usize);
        if e.class != 1
            || (e.width_px, e.height_px) != (h.width_px, h.height_px)
            || pixels.len() < stride * ht
        {
            return None;
        }
        let [u0, v0, u1, v1] = e.window_px.map(|x| x.max(0.0) as usize);
        let (u1, v1) = (u1.min(w), v1.min(ht));
        if u1 < u0 + 3 || v1 <= v0 {
            return None;
        }
        self.profile.clear();
        self.profile.resize(u1 - u0 - 1, 0.0);
        let mut brightness = 0u64;
        for row in pixels.chunks_exact(stride).skip(v0).take(v1 - v0) {
            for (k, acc) in self.profile.iter_mut().enumerate() {
                let u = u0 + k;
                *acc += f32::from(row[u * bpp].abs_diff(row[(u + 1) * bpp]));
                brightness += u64::from(row[u * bpp]);
            }
        }
        let rows = (v1 - v0) as f32;
        let mean = brightness as f32 / (rows * self.profile.len() as f32);
        // The window's own floor: the mean absolute difference sensor noise alone gives
        // (2 sigma / sqrt(pi) for a noise of sigma per pixel), sigma estimated from the window
        // (`harvey_vision::noise`; 0 in a clean frame). Mono frames; colour ones count from 0.
        let sigma = if bpp == 1 {
            Gray::new(pixels, w, ht, stride).map_or(0.0, |g| noise_sigma(&g, Rect::new(u0, v0, u1, v1)))
        } else {
            0.0
        };
        let floor = rows * sigma * 2.0 / std::f32::consts::PI.sqrt();
        for p in &mut self.profile {
            *p = (*p - floor).max(0.0);
        }
        // Dim windows count weaker edges (the same contrast at less light); bright ones never
        // need more than the threshold.
        let threshold = self.threshold * (mean / 128.0).clamp(0.1, 1.0);
        let p = &self.profile;
        self.peaks.clear();
        self.peaks.extend(
            (0..p.len())
                .filter(|&k| {
                    p[k] / rows > threshold
                        && (k == 0 || p[k] >= p[k - 1])
                        && (k + 1 == p.len() || p[k] > p[k + 1])
                })
                .map(|k| (k, p[k] / rows)),
        );
        // Numbered only when sent, so that a gap in `seq` means a lost message.
        let header = Header::new(self.seq + 1, h.stamp_ns);
        let base = LandmarkSighting {
            header,
            frame_seq: h.seq,
            landmark_index: e.landmark_index,
            ..Default::default()
        };
        let peaks = &self.peaks;
        let best = peaks.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((k, strength)) = best else {
            self.seq += 1;
            return Some(LandmarkSighting { kind: SightingKind::NotFound as u32, ..base });
        };
        if peaks.iter().any(|&(j, s)| j != k && s * self.dominance > strength) {
            return None;
        }
        // The edge lies on the boundary between columns u and u + 1.
        let u_edge = (u0 + k + 1) as f64;
        let cx = w as f64 / 2.0;
        self.seq += 1;
        Some(LandmarkSighting {
            kind: SightingKind::Bearing as u32,
            a: ((cx - u_edge) / self.focal_px).atan(),
            a_sd: self.sd_px / self.focal_px,
            ..base
        })
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
    fn a_dim_noisy_edge_is_found_where_it_is() {
        // A 25-level step at column 40 of a dim frame (grey 60 to 85) under noise of sd 8:
        // the old mean absolute difference had a noise floor of 9 levels everywhere.
        let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut noisy = frame(&[(0, 60), (40, 85)]);
        for p in &mut noisy {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let n = ((state & 0xff) as f64 + ((state >> 8) & 0xff) as f64) / 255.0 - 1.0; // sd 0.41
            *p = (f64::from(*p) + n * 8.0 / 0.41).round().clamp(0.0, 255.0) as u8;
        }
        let mut r = LineLandmarks::new(55.4, 12.0);
        let s = r.recognise(&h, &noisy, &expect(30.0, 50.0)).expect("an answer");
        assert_eq!(s.kind, SightingKind::Bearing as u32, "found, not ambiguous");
        assert!((s.a - ((32.0 - 40.0) / 55.4f64).atan()).abs() < 1e-12, "{}", s.a);
    }
}
