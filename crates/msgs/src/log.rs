//! A service's warning or error as a message (`rosout`): what `rcl_interfaces/msg/Log` carries,
//! in fixed-size buffers so it can travel in shared memory.

use crate::{Header, Message, ZeroCopySend};

/// Bytes of a service's name a [`LogLine`] keeps.
pub const LOG_NAME_BYTES: usize = 32;
/// Bytes of text a [`LogLine`] keeps; longer text is cut at a character boundary and ends in `…`.
pub const LOG_TEXT_BYTES: usize = 400;

/// Severity levels as `rcl_interfaces/msg/Log` numbers them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[repr(u8)]
pub enum LogLevel {
    Debug = 10,
    Info = 20,
    Warn = 30,
    Error = 40,
    Fatal = 50,
}

impl LogLevel {
    pub fn from_raw(raw: u8) -> Option<Self> {
        Some(match raw {
            10 => Self::Debug,
            20 => Self::Info,
            30 => Self::Warn,
            40 => Self::Error,
            50 => Self::Fatal,
            _ => return None,
        })
    }

    /// The name log viewers use (`WARN`, `ERROR` …).
    pub fn name(self) -> &'static str {
        match self {
            Self::Debug => "DEBUG",
            Self::Info => "INFO",
            Self::Warn => "WARN",
            Self::Error => "ERROR",
            Self::Fatal => "FATAL",
        }
    }
}

/// One log line of a service (`rosout`), stamped with the tick whose work raised it. `seq`
/// numbers the lines of one service: every service publishes on the topic, each its own count.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_msgs/LogLine")]
pub struct LogLine {
    pub header: Header,
    /// [`LogLevel`] as its number.
    pub level: u8,
    pub name_len: u8,
    pub text_len: u16,
    /// The service's name, UTF-8, `name_len` bytes used.
    pub name: [u8; LOG_NAME_BYTES],
    /// The message with its fields (`text key=value …`), UTF-8, `text_len` bytes used.
    pub text: [u8; LOG_TEXT_BYTES],
}
crate::payloads::message!(LogLine);

impl Default for LogLine {
    fn default() -> Self {
        Self {
            header: Header::default(),
            level: LogLevel::Info as u8,
            name_len: 0,
            text_len: 0,
            name: [0; LOG_NAME_BYTES],
            text: [0; LOG_TEXT_BYTES],
        }
    }
}

/// The longest prefix of `s` that fits `cap` bytes and ends on a character boundary.
fn fit(s: &str, cap: usize) -> &str {
    if s.len() <= cap {
        return s;
    }
    let mut end = cap;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

impl LogLine {
    /// A line of `name` at `level`; a name or text too long for the buffers is cut (the text
    /// marked with a closing `…`).
    pub fn new(header: Header, level: LogLevel, name: &str, text: &str) -> Self {
        let mut line = Self { header, level: level as u8, ..Self::default() };
        let name = fit(name, LOG_NAME_BYTES);
        line.name[..name.len()].copy_from_slice(name.as_bytes());
        line.name_len = name.len() as u8;
        let cut = text.len() > LOG_TEXT_BYTES;
        const ELLIPSIS: &str = "…";
        let body = fit(text, if cut { LOG_TEXT_BYTES - ELLIPSIS.len() } else { LOG_TEXT_BYTES });
        line.text[..body.len()].copy_from_slice(body.as_bytes());
        let mut len = body.len();
        if cut {
            line.text[len..len + ELLIPSIS.len()].copy_from_slice(ELLIPSIS.as_bytes());
            len += ELLIPSIS.len();
        }
        line.text_len = len as u16;
        line
    }

    pub fn level(&self) -> Option<LogLevel> {
        LogLevel::from_raw(self.level)
    }

    /// The service's name (empty if the bytes are not UTF-8: a line from shared memory is not
    /// trusted).
    pub fn name(&self) -> &str {
        let n = usize::from(self.name_len).min(LOG_NAME_BYTES);
        core::str::from_utf8(&self.name[..n]).unwrap_or("")
    }

    /// The text (empty if the bytes are not UTF-8).
    pub fn text(&self) -> &str {
        let n = usize::from(self.text_len).min(LOG_TEXT_BYTES);
        core::str::from_utf8(&self.text[..n]).unwrap_or("")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn name_and_text_round_trip() {
        let l = LogLine::new(Header::new(3, 50_000_000), LogLevel::Warn, "ums", "rejected: too far");
        assert_eq!((l.name(), l.text(), l.level()), ("ums", "rejected: too far", Some(LogLevel::Warn)));
    }

    #[test]
    fn long_text_is_cut_at_a_character_boundary_and_marked() {
        let text = "é".repeat(LOG_TEXT_BYTES);
        let l = LogLine::new(Header::default(), LogLevel::Error, &"n".repeat(40), &text);
        assert_eq!(l.name().len(), LOG_NAME_BYTES);
        assert!(l.text().ends_with('…'), "{}", l.text());
        assert!(l.text().len() <= LOG_TEXT_BYTES);
        assert!(l.text().trim_end_matches('…').chars().all(|c| c == 'é'));
    }

    #[test]
    fn garbled_lengths_and_bytes_read_as_empty_not_a_panic() {
        let mut l = LogLine::new(Header::default(), LogLevel::Warn, "ums", "ok");
        l.text_len = u16::MAX;
        l.name[0] = 0xff;
        assert_eq!(l.name(), "");
        assert!(l.text().starts_with("ok") && l.text().len() == LOG_TEXT_BYTES, "clamped to the buffer");
        assert_eq!(LogLevel::from_raw(7), None);
    }
}
