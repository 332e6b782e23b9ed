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
/// `height` rows of `stride_bytes` each, once per view: a stereo pair (`views = 2`, 003's two
/// cameras taken at one instant) is the left image then the right one, each `height_px` rows,
/// so a reader that knows nothing of views reads the left image.
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
    /// Images one after the other: 0 or 1 one camera's, 2 a stereo pair's (left, right).
    pub views: u32,
    pub reserved: u32,
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
            views: 1,
            reserved: 0,
        }
    }

    /// A stereo pair's header: two `width_px x height_px` images, the left one first.
    pub fn stereo(seq: u64, stamp_ns: u64, width_px: u32, height_px: u32, encoding: Encoding) -> Self {
        Self { views: 2, ..Self::new(seq, stamp_ns, width_px, height_px, encoding) }
    }

    /// How many images the frame carries (a header of an older writer says 0: one).
    pub fn views(&self) -> u32 {
        self.views.max(1)
    }

    /// Bytes of one view's pixels.
    pub fn view_len(&self) -> usize {
        self.stride_bytes as usize * self.height_px as usize
    }

    /// The pixels of view `k` (0 the left camera's) out of the frame's `pixels`; `None` if the
    /// frame has no such view or `pixels` is short of it.
    pub fn view<'a>(&self, pixels: &'a [u8], k: u32) -> Option<&'a [u8]> {
        if k >= self.views() {
            return None;
        }
        let n = self.view_len();
        pixels.get(k as usize * n..(k as usize + 1) * n)
    }

    pub fn encoding(&self) -> Option<Encoding> {
        Encoding::from_raw(self.encoding)
    }

    /// Bytes of pixel data the header describes (every view).
    pub fn payload_len(&self) -> usize {
        self.view_len() * self.views() as usize
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
        assert_eq!(h.views(), 1);
    }

    #[test]
    fn a_stereo_pair_is_the_left_image_then_the_right() {
        let h = FrameHeader::stereo(1, 2, 4, 3, Encoding::Mono8);
        assert_eq!((h.views(), h.view_len(), h.payload_len()), (2, 12, 24));
        let px: Vec<u8> = (0..24).collect();
        assert_eq!(h.view(&px, 0), Some(&px[..12]));
        assert_eq!(h.view(&px, 1), Some(&px[12..]));
        assert_eq!(h.view(&px, 2), None);
        assert_eq!(h.view(&px[..20], 1), None, "short of the right image");
        // An old writer's zeroed field means one view.
        let old = FrameHeader { views: 0, ..FrameHeader::new(1, 2, 4, 3, Encoding::Mono8) };
        assert_eq!((old.views(), old.payload_len()), (1, 12));
    }
}
