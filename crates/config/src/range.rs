//! Ranges of numbers a file may give: an interval with a unit, the check that a value is finite
//! and inside it, and the typed refusal naming the key. The world's, the movers' and the
//! executive's mission checks use them before anything uses a number.

use crate::spans::KeyPath;

/// An interval, each end open or closed, with the unit shown in errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    pub lo: f64,
    pub lo_open: bool,
    pub hi: f64,
    pub hi_open: bool,
    pub unit: &'static str,
}

impl Range {
    /// `[lo, hi]`.
    pub const fn closed(lo: f64, hi: f64, unit: &'static str) -> Range {
        Range { lo, lo_open: false, hi, hi_open: false, unit }
    }

    /// `(lo, hi]`: for sizes that must be positive.
    pub const fn above(lo: f64, hi: f64, unit: &'static str) -> Range {
        Range { lo, lo_open: true, hi, hi_open: false, unit }
    }

    /// `(lo, hi)`.
    pub const fn open(lo: f64, hi: f64, unit: &'static str) -> Range {
        Range { lo, lo_open: true, hi, hi_open: true, unit }
    }

    /// `[lo, hi)`.
    pub const fn below(lo: f64, hi: f64, unit: &'static str) -> Range {
        Range { lo, lo_open: false, hi, hi_open: true, unit }
    }

    /// `[-bound, bound]`.
    pub const fn within(bound: f64, unit: &'static str) -> Range {
        Range::closed(-bound, bound, unit)
    }

    /// Whether `v` lies inside (never for NaN or an infinity).
    pub fn contains(&self, v: f64) -> bool {
        let above_lo = if self.lo_open { v > self.lo } else { v >= self.lo };
        let below_hi = if self.hi_open { v < self.hi } else { v <= self.hi };
        v.is_finite() && above_lo && below_hi
    }
}

impl std::fmt::Display for Range {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (open, close) = (if self.lo_open { '(' } else { '[' }, if self.hi_open { ')' } else { ']' });
        write!(f, "{open}{}, {}{close}", self.lo, self.hi)?;
        if !self.unit.is_empty() {
            write!(f, " {}", self.unit)?;
        }
        Ok(())
    }
}

/// A number of the file outside its range, or a list longer than a service may be made to
/// allocate: the key and why.
#[derive(Debug, Clone, PartialEq)]
pub struct OutOfRange {
    pub key: KeyPath,
    pub detail: String,
}

/// `v` as a file would give it: `0.5`, `4000000000`, `1e308`, `1e-300`, `NaN`, `inf`.
fn shown(v: f64) -> String {
    let plain = v == 0.0 || (1e-6..1e15).contains(&v.abs());
    if plain { format!("{v}") } else { format!("{v:?}") }
}

/// `v` at `key` is finite and in `range`.
pub fn check(key: &KeyPath, v: f64, range: &Range) -> Result<(), OutOfRange> {
    if range.contains(v) {
        return Ok(());
    }
    let what = if v.is_finite() { "outside" } else { "not a finite number in" };
    Err(OutOfRange { key: key.clone(), detail: format!("{} is {what} {range}", shown(v)) })
}

/// Each of `vs`, at `key[i]`, is finite and in `range`.
pub fn check_all(key: &KeyPath, vs: &[f64], range: &Range) -> Result<(), OutOfRange> {
    vs.iter().enumerate().try_for_each(|(i, v)| check(&key.index(i), *v, range))
}

/// The integer `v` at `key` is in `lo..=hi` (`unit` shown in the error).
pub fn check_int(key: &KeyPath, v: u32, lo: u32, hi: u32, unit: &str) -> Result<(), OutOfRange> {
    if (lo..=hi).contains(&v) {
        return Ok(());
    }
    let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
    Err(OutOfRange { key: key.clone(), detail: format!("{v} is outside [{lo}, {hi}]{unit}") })
}

/// The list at `key` has at most `max` entries (else the first one too many is named).
pub fn check_len(key: &KeyPath, len: usize, max: usize, what: &str) -> Result<(), OutOfRange> {
    if len <= max {
        return Ok(());
    }
    Err(OutOfRange { key: key.index(max), detail: format!("{len} {what}, more than the {max} allowed") })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_refuse_what_is_outside_and_every_non_finite_number() {
        let r = Range::above(0.0, 90.0, "deg");
        assert!(r.contains(90.0) && r.contains(1e-9));
        assert!(!r.contains(0.0) && !r.contains(f64::NAN) && !r.contains(f64::INFINITY));
        assert!(!Range::open(0.0, 90.0, "deg").contains(90.0));
        assert!(Range::below(0.0, 1.0, "").contains(0.0) && !Range::below(0.0, 1.0, "").contains(1.0));
        assert_eq!(r.to_string(), "(0, 90] deg");
        let key = KeyPath::default().key("robot").key("sonar_beam_width_deg");
        let e = check(&key, f64::NAN, &r).expect_err("NaN");
        assert_eq!(e.detail, "NaN is not a finite number in (0, 90] deg");
        assert_eq!(e.key.to_string(), "robot.sonar_beam_width_deg");
        assert_eq!(check(&key, -1e-300, &r).expect_err("tiny").detail, "-1e-300 is outside (0, 90] deg");
        assert_eq!(
            check_int(&key, 0, 1, 100, "poles").expect_err("zero").detail,
            "0 is outside [1, 100] poles"
        );
        let e = check_len(&KeyPath::default().key("wall"), 5, 3, "walls").expect_err("too many");
        assert_eq!(
            (e.key.to_string(), e.detail.as_str()),
            ("wall[3]".to_owned(), "5 walls, more than the 3 allowed")
        );
    }
}
