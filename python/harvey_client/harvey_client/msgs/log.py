"""A service's warning or error as a message (`rosout`), in fixed-size buffers, as
`crates/msgs/src/log.rs`."""

from typing import Any, Dict

from .base import Header, Message, c_u8, c_u16

LOG_NAME_BYTES = 32
LOG_TEXT_BYTES = 400

# The level, carried as its `u8` discriminant.
LOG_LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}


class LogLine(Message):
    _fields_ = [
        ("header", Header),
        ("level", c_u8),
        ("name_len", c_u8),
        ("text_len", c_u16),
        ("name", c_u8 * LOG_NAME_BYTES),
        ("text", c_u8 * LOG_TEXT_BYTES),
    ]
    _type_name = "harvey_msgs/LogLine"

    @property
    def service(self) -> str:
        """The service's name (as Rust's `LogLine::name()`: empty if not UTF-8)."""
        n = min(self.name_len, LOG_NAME_BYTES)
        try:
            return bytes(self.name[:n]).decode("utf-8")
        except UnicodeDecodeError:
            return ""

    @property
    def message(self) -> str:
        """The text with its fields (empty if not UTF-8)."""
        n = min(self.text_len, LOG_TEXT_BYTES)
        try:
            return bytes(self.text[:n]).decode("utf-8")
        except UnicodeDecodeError:
            return ""

    @property
    def level_name(self) -> str:
        return LOG_LEVELS.get(self.level, str(self.level))

    def to_dict(self) -> Dict[str, Any]:
        d = super().to_dict()
        # The buffers as the strings they hold.
        d["name"] = self.service
        d["text"] = self.message
        return d
