//! A service's log line as ROS 2's `rcl_interfaces/msg/Log` (what `/rosout` carries), so
//! Foxglove's Log panel and ROS 2 tools read it as they read any node's.

use harvey_msgs::{Header, LogLine};

use crate::codec::{Cdr, CdrError, CdrReader, CdrWriter};
use crate::schema::Def;
use crate::types::{Ros2Msg, TIME};

/// `rcl_interfaces/msg/Log` as ROS 2 Jazzy defines it (its comments left out).
static LOG: Def = Def {
    name: "rcl_interfaces/Log",
    text: "byte DEBUG=10\nbyte INFO=20\nbyte WARN=30\nbyte ERROR=40\nbyte FATAL=50\n\
           builtin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\nstring file\n\
           string function\nuint32 line\n",
    deps: &[&TIME],
};

/// The standard type has no sequence number: a decoded line's `seq` is 0 (the recording's
/// MCAP `sequence` carries it). `file`, `function` and `line` are left empty: a recording must
/// not change when code moves.
impl Cdr for LogLine {
    fn write(&self, w: &mut CdrWriter) {
        w.prim((self.header.stamp_ns / 1_000_000_000) as i32);
        w.prim((self.header.stamp_ns % 1_000_000_000) as u32);
        w.prim(self.level);
        w.string(self.name());
        w.string(self.text());
        w.string("");
        w.string("");
        w.prim(0u32);
    }

    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let sec = r.prim::<i32>()?;
        let nanosec = r.prim::<u32>()?;
        let level = r.prim::<u8>()?;
        let name = r.string()?;
        let msg = r.string()?;
        let _file = r.string()?;
        let _function = r.string()?;
        let _line = r.prim::<u32>()?;
        let stamp_ns = u64::try_from(sec).unwrap_or(0) * 1_000_000_000 + u64::from(nanosec);
        let mut line = LogLine::new(Header::new(0, stamp_ns), harvey_msgs::LogLevel::Info, &name, &msg);
        line.level = level;
        Ok(line)
    }
}

impl Ros2Msg for LogLine {
    const DEF: &'static Def = &LOG;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{decode, encode, full_text};
    use harvey_msgs::LogLevel;

    #[test]
    fn a_line_follows_rcl_interfaces_log_and_round_trips() {
        let line =
            LogLine::new(Header::new(0, 2_500_000_000), LogLevel::Error, "executive", "mission failed");
        let bytes = encode(&line, Vec::new());
        let mut r = CdrReader::new(&bytes).expect("encapsulation");
        assert_eq!((r.prim::<i32>().expect("sec"), r.prim::<u32>().expect("ns")), (2, 500_000_000));
        assert_eq!(r.prim::<u8>().expect("level"), 40);
        assert_eq!(r.string().expect("name"), "executive");
        assert_eq!(r.string().expect("msg"), "mission failed");
        assert_eq!(
            (r.string().expect("file"), r.string().expect("function")),
            (String::new(), String::new())
        );
        assert_eq!(r.prim::<u32>().expect("line"), 0);
        assert_eq!(r.remaining(), 0);
        assert_eq!(decode::<LogLine>(&bytes).expect("decodes"), line);
        assert!(decode::<LogLine>(&bytes[..bytes.len() - 1]).is_err(), "truncated must fail");
        assert_eq!(LOG.schema_name(), "rcl_interfaces/msg/Log");
        assert!(full_text(&LOG).contains("MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"));
    }
}
