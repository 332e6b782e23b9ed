//! Camera frames: the `FrameHeader` user header that travels beside a `[u8]` pixel slice.

use crate::ZeroCopySend;

/// Pixel encodings, named as in `sensor_msgs/msg/Image`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum Encoding {
    Mono8 = 1,
    Rgb8 = 2,
}

impl Encoding {
    pub const fn bytes_per_pixel(self) -> u32 {
        match self {
            Encoding::Mono8 => 1,
            Encoding::Rgb8 => 3,
        }
    }

    /// The ROS 2 `sensor_msgs/msg/Image.encoding` string.
    pub const fn ros_name(self) -> &'static str {
        match self {
            Encoding::Mono8 => "mono8",
            Encoding::Rgb8 => "rgb8",
        }
    }

    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(Encoding::Mono8),
            2 => Some(Encoding::Rgb8),
            _ => None,
        }
    }

    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "mono8" => Some(Encoding::Mono8),
            "rgb8" => Some(Encoding::Rgb8),
            _ => None,
        }
    }
}

/// The user header of a camera frame. The pixels follow as the sample's `[u8]` payload,
/// `height` rows of `stride_bytes` each.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/FrameHeader")]
pub struct FrameHeader {
    pub seq: u64,
    pub stamp_ns: u64,
    pub width_px: u32,
    pub height_px: u32,
    pub stride_bytes: u32,
    /// [`Encoding`] as its `u32` discriminant (0 = unset).
    pub encoding: u32,
}

impl FrameHeader {
    pub fn new(seq: u64, stamp_ns: u64, width_px: u32, height_px: u32, encoding: Encoding) -> Self {
        Self {
            seq,
            stamp_ns,
            width_px,
            height_px,
            stride_bytes: width_px * encoding.bytes_per_pixel(),
            encoding: encoding as u32,
        }
    }

    pub fn encoding(&self) -> Option<Encoding> {
        Encoding::from_raw(self.encoding)
    }

    /// Bytes of pixel data the header describes.
    pub fn payload_len(&self) -> usize {
        self.stride_bytes as usize * self.height_px as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stride_and_length_follow_encoding() {
        let h = FrameHeader::new(1, 2, 1920, 1080, Encoding::Rgb8);
        assert_eq!(h.stride_bytes, 5760);
        assert_eq!(h.payload_len(), 6_220_800);
        assert_eq!(h.encoding(), Some(Encoding::Rgb8));
        assert_eq!(Encoding::parse("mono8"), Some(Encoding::Mono8));
        assert_eq!(Encoding::from_raw(9), None);
    }
}
