"""Camera frames: the `FrameHeader` user header that travels beside a `[u8]` pixel slice, as
`crates/msgs/src/frame.rs`."""

from .base import Message, c_u32, c_u64

# The encoding, carried as its `u32` discriminant, and its bytes per pixel.
ENCODINGS = {1: "mono8", 2: "rgb8"}
BYTES_PER_PIXEL = {1: 1, 2: 3}


class FrameHeader(Message):
    """The user header of a camera frame; the pixels follow as the sample's `[u8]` payload,
    `height_px` rows of `stride_bytes` each, once per view (a stereo pair: `views` 2, the left
    image then the right one)."""

    _fields_ = [
        ("seq", c_u64),
        ("stamp_ns", c_u64),
        ("width_px", c_u32),
        ("height_px", c_u32),
        ("stride_bytes", c_u32),
        ("encoding", c_u32),
        ("views", c_u32),
        ("reserved", c_u32),
    ]
    _type_name = "harvey_msgs/FrameHeader"

    @property
    def encoding_name(self) -> str:
        return ENCODINGS.get(self.encoding, "")

    def view_count(self) -> int:
        """How many images the frame carries (0 from an older writer means one)."""
        return max(1, self.views)

    def payload_len(self) -> int:
        return self.stride_bytes * self.height_px * self.view_count()
