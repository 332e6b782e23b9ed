//! A streaming frame decoder that resynchronises on `$` after garbage or cut frames and counts
//! what it threw away.

use crate::MAX_FRAME_LEN;
use crate::frame::{FrameError, Line, parse_frame};

/// What the decoder has seen so far.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct DecoderStats {
    pub frames: u64,
    /// Bytes outside any frame.
    pub garbage_bytes: u64,
    /// Frames cut short by the start of another, or longer than [`MAX_FRAME_LEN`].
    pub truncated: u64,
    pub bad_checksums: u64,
    pub malformed: u64,
}

/// Turns a byte stream into lines. Feed it whatever the serial port returns.
#[derive(Debug, Default)]
pub struct Decoder {
    buf: Vec<u8>,
    in_frame: bool,
    stats: DecoderStats,
}

impl Decoder {
    pub fn new() -> Self {
        Self { buf: Vec::with_capacity(MAX_FRAME_LEN), ..Self::default() }
    }

    pub fn stats(&self) -> DecoderStats {
        self.stats
    }

    /// Consumes `bytes`, calling `out` for each complete frame: the line, or why it was rejected.
    pub fn push(&mut self, bytes: &[u8], mut out: impl FnMut(Result<Line, FrameError>)) {
        for &b in bytes {
            if b == b'$' {
                if self.in_frame {
                    self.stats.truncated += 1;
                    out(Err(FrameError::Malformed("frame cut short by the next `$`".into())));
                }
                self.in_frame = true;
                self.buf.clear();
                continue;
            }
            if !self.in_frame {
                self.stats.garbage_bytes += 1;
                continue;
            }
            if b == b'\n' {
                self.in_frame = false;
                out(self.finish());
                continue;
            }
            if self.buf.len() + 2 >= MAX_FRAME_LEN {
                self.in_frame = false;
                self.stats.truncated += 1;
                out(Err(FrameError::Malformed(format!("frame longer than {MAX_FRAME_LEN} bytes"))));
                continue;
            }
            self.buf.push(b);
        }
    }

    fn finish(&mut self) -> Result<Line, FrameError> {
        let result = match self.buf.strip_suffix(b"\r") {
            Some(inner) => parse_frame(inner),
            None => Err(FrameError::Malformed("frame does not end in CR LF".into())),
        };
        match &result {
            Ok(_) => self.stats.frames += 1,
            Err(FrameError::Checksum { .. }) => self.stats.bad_checksums += 1,
            Err(FrameError::Malformed(_)) => self.stats.malformed += 1,
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Command, Report, encode};

    fn decode_all(bytes: &[u8]) -> (Vec<Line>, DecoderStats) {
        let mut d = Decoder::new();
        let mut lines = Vec::new();
        d.push(bytes, |r| {
            if let Ok(l) = r {
                lines.push(l)
            }
        });
        (lines, d.stats())
    }

    fn samples() -> Vec<Line> {
        vec![
            Line::Command(Command::Move { id: 7, hundredths_ft: -123 }),
            Line::Command(Command::Turn { id: 8, tenths_deg: 900 }),
            Line::Command(Command::Stop { id: 9 }),
            Line::Command(Command::Velocity { id: 10, hundredths_ft_per_s: 5, tenths_deg_per_s: -30 }),
            Line::Report(Report::Encoders {
                time_ms: 123_456,
                x_hundredths_ft: 10,
                y_hundredths_ft: -4,
                heading_tenths_deg: 3599,
                moving: true,
                command_id: 8,
            }),
            Line::Report(Report::Sonar {
                time_ms: 99,
                bank: 2,
                ranges_tenths_ft: [0, 1, 2, 30, 255, 254, 7, 100],
            }),
            Line::Report(Report::Ack { id: 3 }),
            Line::Report(Report::Nak { id: 4, reason: crate::NakReason::OutOfRange }),
            Line::Tick { time_ms: 1_250 },
            Line::Sync { time_ms: 1_250 },
            Line::Heartbeat { time_ms: 1_300 },
        ]
    }

    #[test]
    fn every_line_round_trips() {
        let bytes: String = samples().iter().map(encode).collect();
        let (lines, stats) = decode_all(bytes.as_bytes());
        assert_eq!(lines, samples());
        assert_eq!(stats, DecoderStats { frames: 11, ..DecoderStats::default() });
    }

    #[test]
    fn garbage_and_cut_frames_lose_no_valid_frame() {
        let good = samples();
        let mut stream = b"\x00\xffnoise".to_vec();
        for (i, line) in good.iter().enumerate() {
            let text = encode(line);
            stream.extend_from_slice(&text.as_bytes()[..text.len() / 2]); // a cut copy...
            if i % 2 == 0 {
                stream.extend_from_slice(b"\r\n"); // ...sometimes closed early
            }
            stream.extend_from_slice(text.as_bytes()); // ...then the real frame
            stream.extend_from_slice(b"junk*");
        }
        let (lines, stats) = decode_all(&stream);
        assert_eq!(lines, good);
        assert_eq!(stats.frames, 11);
        assert_eq!(stats.truncated + stats.malformed + stats.bad_checksums, 11);
        assert!(stats.garbage_bytes >= 7 + 5 * 11);
    }

    #[test]
    fn the_documented_example_frames_are_exact() {
        assert_eq!(encode(&Line::Command(Command::Move { id: 1, hundredths_ft: 400 })), "$MV 1 400*1E\r\n");
        assert_eq!(encode(&Line::Report(Report::Ack { id: 1 })), "$AK 1*1B\r\n");
        let en = Report::Encoders {
            time_ms: 1250,
            x_hundredths_ft: 41,
            y_hundredths_ft: 0,
            heading_tenths_deg: 0,
            moving: true,
            command_id: 1,
        };
        assert_eq!(encode(&Line::Report(en)), "$EN 1250 41 0 0 1 1*08\r\n");
    }

    #[test]
    fn a_flipped_bit_is_a_checksum_error() {
        let mut text = encode(&samples()[0]).into_bytes();
        text[3] ^= 0x01;
        let mut d = Decoder::new();
        let mut results = Vec::new();
        d.push(&text, |r| results.push(r));
        assert!(matches!(results.as_slice(), [Err(FrameError::Checksum { .. })]));
        assert_eq!(d.stats().bad_checksums, 1);
    }

    #[test]
    fn frames_may_arrive_one_byte_at_a_time() {
        let text = encode(&samples()[4]);
        let mut d = Decoder::new();
        let mut lines = Vec::new();
        for b in text.as_bytes() {
            d.push(std::slice::from_ref(b), |r| lines.push(r));
        }
        assert_eq!(lines, vec![Ok(samples()[4])]);
    }

    #[test]
    fn out_of_range_fields_are_malformed() {
        for body in [
            "SN 1 3 0 0 0 0 0 0 0 0",
            "SN 1 0 0 0 0 0 0 0 0 256",
            "EN 1 0 0 0 2 0",
            "MV 1",
            "XX 1",
            "MV 1 99999999999",
        ] {
            let cs = body.bytes().fold(0u8, |a, b| a ^ b);
            let frame = format!("${body}*{cs:02X}\r\n");
            let mut d = Decoder::new();
            let mut results = Vec::new();
            d.push(frame.as_bytes(), |r| results.push(r));
            assert!(matches!(results.as_slice(), [Err(FrameError::Malformed(_))]), "{body}: {results:?}");
        }
    }
}
