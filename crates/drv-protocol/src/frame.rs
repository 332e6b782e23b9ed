//! One protocol line: its fields, its text form and its checksum.

use std::fmt::Write;

/// Sonar range meaning "no echo within the 25.5 ft limit" (001 §3: ranges in tenths of a foot,
/// 25.5 ft maximum, so the largest reading is 255).
pub const SONAR_NO_ECHO: u16 = 255;

/// Host → DRV.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// Translate along the current heading by `hundredths_ft` (negative: backwards).
    Move { id: u32, hundredths_ft: i32 },
    /// Rotate in place by `tenths_deg`, counter-clockwise positive.
    Turn { id: u32, tenths_deg: i32 },
    /// Stop at once, abandoning any motion.
    Stop { id: u32 },
    /// Drive at a steady speed until the next command.
    Velocity { id: u32, hundredths_ft_per_s: i32, tenths_deg_per_s: i32 },
}

/// DRV → host.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Report {
    /// Shaft-encoder dead reckoning: position and heading since power-up.
    Encoders {
        time_ms: u64,
        x_hundredths_ft: i32,
        y_hundredths_ft: i32,
        heading_tenths_deg: i32,
        moving: bool,
        command_id: u32,
    },
    /// One bank of eight sensors fired together; sensor `bank + 3 * i` read `ranges[i]`.
    Sonar { time_ms: u64, bank: u8, ranges_tenths_ft: [u16; 8] },
    /// A command was accepted.
    Ack { id: u32 },
    /// A command was refused; `reason` is a short word.
    Nak { id: u32, reason: NakReason },
}

/// Why the DRV refused a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NakReason {
    OutOfRange,
    Busy,
}

/// Either direction's line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Line {
    Command(Command),
    Report(Report),
    /// DRV → host, deterministic mode only (a Harvey extension; see `docs/drv-protocol.md`):
    /// every report of the tick ending at `time_ms` has been sent.
    Tick {
        time_ms: u64,
    },
    /// Host → DRV, deterministic mode only: every command of the tick ending at `time_ms` has
    /// been sent; the DRV may simulate the next tick.
    Sync {
        time_ms: u64,
    },
    /// Host → DRV, real time (a Harvey extension): the host, and the executive behind it, is
    /// alive at the DRV's time `time_ms`; it feeds the DRV's watchdog between commands.
    Heartbeat {
        time_ms: u64,
    },
}

/// What is wrong with a received frame.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    #[error("checksum mismatch: frame says {expected:02X}, body sums to {actual:02X}")]
    Checksum { expected: u8, actual: u8 },
    #[error("malformed frame: {0}")]
    Malformed(String),
}

fn checksum(body: &[u8]) -> u8 {
    body.iter().fold(0, |acc, b| acc ^ b)
}

/// The full frame for `line`, `$` through `\r\n`.
pub fn encode(line: &Line) -> String {
    let mut body = String::with_capacity(64);
    // Writing into a String cannot fail.
    let _ = match line {
        Line::Command(Command::Move { id, hundredths_ft }) => {
            write!(body, "MV {id} {hundredths_ft}")
        }
        Line::Command(Command::Turn { id, tenths_deg }) => write!(body, "TN {id} {tenths_deg}"),
        Line::Command(Command::Stop { id }) => write!(body, "ST {id}"),
        Line::Command(Command::Velocity { id, hundredths_ft_per_s, tenths_deg_per_s }) => {
            write!(body, "VL {id} {hundredths_ft_per_s} {tenths_deg_per_s}")
        }
        Line::Report(Report::Encoders {
            time_ms,
            x_hundredths_ft,
            y_hundredths_ft,
            heading_tenths_deg,
            moving,
            command_id,
        }) => {
            write!(
                body,
                "EN {time_ms} {x_hundredths_ft} {y_hundredths_ft} {heading_tenths_deg} {} {command_id}",
                u8::from(*moving)
            )
        }
        Line::Report(Report::Sonar { time_ms, bank, ranges_tenths_ft }) => {
            let _ = write!(body, "SN {time_ms} {bank}");
            ranges_tenths_ft.iter().try_for_each(|r| write!(body, " {r}"))
        }
        Line::Report(Report::Ack { id }) => write!(body, "AK {id}"),
        Line::Tick { time_ms } => write!(body, "TK {time_ms}"),
        Line::Sync { time_ms } => write!(body, "SY {time_ms}"),
        Line::Heartbeat { time_ms } => write!(body, "HB {time_ms}"),
        Line::Report(Report::Nak { id, reason }) => write!(
            body,
            "NK {id} {}",
            match reason {
                NakReason::OutOfRange => "RANGE",
                NakReason::Busy => "BUSY",
            }
        ),
    };
    format!("${body}*{:02X}\r\n", checksum(body.as_bytes()))
}

/// Parses the bytes between `$` and `\r\n` (exclusive): `BODY*CS`.
pub(crate) fn parse_frame(inner: &[u8]) -> Result<Line, FrameError> {
    let bad = |why: &str| FrameError::Malformed(why.to_owned());
    let star = inner.iter().rposition(|&b| b == b'*').ok_or_else(|| bad("no `*` before checksum"))?;
    let (body, cs) = (&inner[..star], &inner[star + 1..]);
    let cs = std::str::from_utf8(cs)
        .ok()
        .filter(|s| s.len() == 2)
        .ok_or_else(|| bad("checksum is not 2 hex digits"))?;
    let expected = u8::from_str_radix(cs, 16).map_err(|_| bad("checksum is not 2 hex digits"))?;
    let actual = checksum(body);
    if expected != actual {
        return Err(FrameError::Checksum { expected, actual });
    }
    let body = std::str::from_utf8(body).map_err(|_| bad("body is not ASCII"))?;
    let mut fields = body.split(' ');
    let tag = fields.next().unwrap_or_default();
    let nums: Vec<&str> = fields.collect();
    let num = |i: usize| -> Result<i64, FrameError> {
        nums.get(i)
            .ok_or_else(|| FrameError::Malformed(format!("`{tag}` lacks field {}", i + 1)))?
            .parse::<i64>()
            .map_err(|_| FrameError::Malformed(format!("`{tag}` field {} is not an integer", i + 1)))
    };
    let arity = |n: usize| -> Result<(), FrameError> {
        if nums.len() == n {
            Ok(())
        } else {
            Err(FrameError::Malformed(format!("`{tag}` takes {n} fields, got {}", nums.len())))
        }
    };
    let fit = |v: i64, what: &str| -> Result<i32, FrameError> {
        i32::try_from(v).map_err(|_| FrameError::Malformed(format!("`{tag}` {what} out of range")))
    };
    let id = |i| num(i).and_then(|v| u32::try_from(v).map_err(|_| bad("id out of range")));
    let time = |i| num(i).and_then(|v| u64::try_from(v).map_err(|_| bad("time out of range")));
    Ok(match tag {
        "MV" => {
            arity(2)?;
            Line::Command(Command::Move { id: id(0)?, hundredths_ft: fit(num(1)?, "distance")? })
        }
        "TN" => {
            arity(2)?;
            Line::Command(Command::Turn { id: id(0)?, tenths_deg: fit(num(1)?, "angle")? })
        }
        "ST" => {
            arity(1)?;
            Line::Command(Command::Stop { id: id(0)? })
        }
        "VL" => {
            arity(3)?;
            Line::Command(Command::Velocity {
                id: id(0)?,
                hundredths_ft_per_s: fit(num(1)?, "speed")?,
                tenths_deg_per_s: fit(num(2)?, "rate")?,
            })
        }
        "EN" => {
            arity(6)?;
            let moving = match num(4)? {
                0 => false,
                1 => true,
                _ => return Err(bad("`EN` moving flag must be 0 or 1")),
            };
            Line::Report(Report::Encoders {
                time_ms: time(0)?,
                x_hundredths_ft: fit(num(1)?, "x")?,
                y_hundredths_ft: fit(num(2)?, "y")?,
                heading_tenths_deg: fit(num(3)?, "heading")?,
                moving,
                command_id: id(5)?,
            })
        }
        "SN" => {
            arity(10)?;
            let bank = u8::try_from(num(1)?)
                .ok()
                .filter(|b| *b < 3)
                .ok_or_else(|| bad("`SN` bank must be 0, 1 or 2"))?;
            let mut ranges_tenths_ft = [0u16; 8];
            for (i, r) in ranges_tenths_ft.iter_mut().enumerate() {
                *r = u16::try_from(num(2 + i)?)
                    .ok()
                    .filter(|r| *r <= SONAR_NO_ECHO)
                    .ok_or_else(|| bad("`SN` range above 255"))?;
            }
            Line::Report(Report::Sonar { time_ms: time(0)?, bank, ranges_tenths_ft })
        }
        "TK" => {
            arity(1)?;
            Line::Tick { time_ms: time(0)? }
        }
        "SY" => {
            arity(1)?;
            Line::Sync { time_ms: time(0)? }
        }
        "HB" => {
            arity(1)?;
            Line::Heartbeat { time_ms: time(0)? }
        }
        "AK" => {
            arity(1)?;
            Line::Report(Report::Ack { id: id(0)? })
        }
        "NK" => {
            arity(2)?;
            let reason = match nums[1] {
                "RANGE" => NakReason::OutOfRange,
                "BUSY" => NakReason::Busy,
                other => {
                    return Err(FrameError::Malformed(format!("`NK` reason `{other}` unknown")));
                }
            };
            Line::Report(Report::Nak { id: id(0)?, reason })
        }
        other => {
            return Err(FrameError::Malformed(format!("unknown tag `{}`", other.escape_debug())));
        }
    })
}
