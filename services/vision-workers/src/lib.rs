//! Vision workers' logic. This first worker finds vertical edges (door frames, wall corners) in a
//! horizontal band of the frame, read in place; the papers' algorithms join it in their issue.

pub mod node;
use harvey_msgs::{Detections, Feature, FrameHeader, Header, MAX_FEATURES};

/// Algorithm ids carried in [`Detections::algorithm`].
pub mod depth;
pub mod dispatch;
pub mod landmarks;
pub mod odometry;
pub mod odometry_config;
pub mod path;
pub mod poles;
pub mod templates;

pub const ALGO_VERTICAL_EDGES: u32 = 1;

/// Why a frame could not be searched for edges.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrameError {
    #[error("frame {seq}: unknown encoding {encoding}")]
    UnknownEncoding { seq: u64, encoding: u32 },
    /// The header's size and stride ask for more bytes than the frame holds (or are degenerate).
    #[error("frame {seq}: {width_px}x{height_px} stride {stride_bytes} does not fit {len} bytes")]
    DoesNotFit { seq: u64, width_px: usize, height_px: usize, stride_bytes: usize, len: usize },
}

/// Finds vertical edges in a band of rows; keeps its scratch between frames.
#[derive(Debug)]
pub struct VerticalEdges {
    /// Half-height of the band around the image centre row.
    pub band_half_rows: u32,
    /// Mean absolute horizontal difference (grey levels) an edge must exceed.
    pub threshold: f32,
    sums: Vec<u32>,
    found: Vec<Feature>,
    seq: u64,
}

impl VerticalEdges {
    /// How many messages it has numbered: kept across a restart (a checkpoint), so that a
    /// restarted worker numbers on.
    pub fn numbered(&self) -> u64 {
        self.seq
    }

    pub fn number_from(&mut self, seq: u64) {
        self.seq = seq;
    }

    pub fn new(band_half_rows: u32, threshold: f32) -> Self {
        Self { band_half_rows, threshold, sums: Vec::new(), found: Vec::new(), seq: 0 }
    }

    /// Runs on one frame (mono8 or rgb8, first channel used).
    pub fn run(&mut self, h: &FrameHeader, pixels: &[u8]) -> Result<Detections, FrameError> {
        let bpp = h
            .encoding()
            .ok_or(FrameError::UnknownEncoding { seq: h.seq, encoding: h.encoding })?
            .bytes_per_pixel() as usize;
        let (w, ht, stride) = (h.width_px as usize, h.height_px as usize, h.stride_bytes as usize);
        if w < 3 || ht == 0 || stride < w * bpp || pixels.len() < stride * ht {
            return Err(FrameError::DoesNotFit {
                seq: h.seq,
                width_px: w,
                height_px: ht,
                stride_bytes: stride,
                len: pixels.len(),
            });
        }
        let mid = ht / 2;
        let half = (self.band_half_rows as usize).min(mid);
        let rows = (mid - half)..(mid + half).max(mid + 1).min(ht);
        // Summed as integers (mono8 rows vectorise): the same values an f32 sum takes, which
        // is exact while a column's sum stays under 2^24 (255 x 65 793 rows).
        self.sums.clear();
        self.sums.resize(w - 1, 0);
        for v in rows.clone() {
            let row = &pixels[v * stride..v * stride + w * bpp];
            if bpp == 1 {
                for ((acc, a), b) in self.sums.iter_mut().zip(row).zip(&row[1..]) {
                    *acc += u32::from(a.abs_diff(*b));
                }
            } else {
                for (u, acc) in self.sums.iter_mut().enumerate() {
                    *acc += u32::from(row[u * bpp].abs_diff(row[(u + 1) * bpp]));
                }
            }
        }
        let n_rows = rows.len() as f32;
        let mut features = [Feature::default(); MAX_FEATURES];
        // A column's mean difference over the band (0 beside the frame).
        let sums = &self.sums;
        let mean = |u: usize| sums.get(u).map_or(0.0, |&s| s as f32 / n_rows);
        self.found.clear();
        self.found.extend((0..w - 1).filter_map(|u| {
            let s = mean(u);
            let left = if u > 0 { mean(u - 1) } else { 0.0 };
            let right = mean(u + 1);
            (s > self.threshold && s >= left && s > right).then_some(Feature {
                x_px: u as f32 + 1.0,
                y_px: mid as f32,
                score: s,
                kind: ALGO_VERTICAL_EDGES,
            })
        }));
        let found = &mut self.found;
        found.sort_by(|a, b| b.score.total_cmp(&a.score).then(a.x_px.total_cmp(&b.x_px)));
        found.truncate(MAX_FEATURES);
        features[..found.len()].copy_from_slice(found);
        self.seq += 1;
        Ok(Detections {
            header: Header::new(self.seq, h.stamp_ns),
            frame_seq: h.seq,
            algorithm: ALGO_VERTICAL_EDGES,
            count: found.len() as u32,
            confidence: (found.len() as f32 / 4.0).min(1.0),
            reserved: 0,
            features,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::Encoding;

    #[test]
    fn finds_a_step_edge_where_it_is() {
        let (w, h) = (64u32, 48u32);
        let header = FrameHeader::new(5, 77, w, h, Encoding::Mono8);
        let img: Vec<u8> = (0..w * h).map(|i| if i % w < 40 { 50 } else { 200 }).collect();
        let mut e = VerticalEdges::new(8, 20.0);
        let d = e.run(&header, &img).expect("runs");
        assert_eq!((d.count, d.frame_seq, d.header.stamp_ns), (1, 5, 77));
        assert_eq!(d.features[0].x_px, 40.0);
        assert!((d.features[0].score - 150.0).abs() < 1e-3);
    }

    #[test]
    fn an_rgb_frame_gives_what_its_first_channel_as_mono_gives() {
        let (w, h) = (97u32, 40u32);
        // Steps and a ramp, with a little texture; the other channels differ.
        let grey = |i: u32| {
            let (u, v) = (i % w, i / w);
            let base = if u < 30 {
                40
            } else if u < 61 {
                170
            } else {
                90 + 2 * (u - 61)
            };
            (base + (u * 7 + v * 13) % 5) as u8
        };
        let mono: Vec<u8> = (0..w * h).map(grey).collect();
        let rgb: Vec<u8> = (0..w * h).flat_map(|i| [grey(i), 255 - grey(i), (i % 251) as u8]).collect();
        let mut e = VerticalEdges::new(12, 10.0);
        let a = e.run(&FrameHeader::new(1, 0, w, h, Encoding::Mono8), &mono).expect("mono");
        let b = e.run(&FrameHeader::new(2, 0, w, h, Encoding::Rgb8), &rgb).expect("rgb");
        assert!(a.count >= 2, "{a:?}");
        assert_eq!((a.count, a.features), (b.count, b.features));
    }

    #[test]
    fn malformed_frames_are_errors_not_crashes() {
        let mut e = VerticalEdges::new(8, 20.0);
        let header = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
        let short = e.run(&header, &[0u8; 100]).expect_err("too short");
        assert_eq!(short.to_string(), "frame 1: 64x48 stride 64 does not fit 100 bytes");
        let bad = FrameHeader { encoding: 99, ..header };
        let unknown = e.run(&bad, &[0u8; 64 * 48]).expect_err("encoding 99");
        assert_eq!(unknown.to_string(), "frame 1: unknown encoding 99");
    }
}
