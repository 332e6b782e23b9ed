//! Comparing two recordings message by message: the check behind deterministic runs and
//! `harvey replay --check`. Two recordings agree when the same messages (topic, log time and
//! payload bytes) come in the same order; chunking, compression and metadata may differ.

use std::path::Path;

use crate::{Recording, RecordingError};

/// Where two recordings first part ways.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Difference {
    /// Index of the message among those compared.
    pub index: usize,
    pub detail: String,
}

/// The outcome of a comparison.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Comparison {
    /// Messages compared (of the first recording).
    pub messages: usize,
    pub first_difference: Option<Difference>,
}

/// One recorded message: topic (without the leading `/`), log time and payload.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Record {
    pub topic: String,
    pub log_time: u64,
    pub data: Vec<u8>,
}

/// Every message of `path` whose topic `keep` accepts, in file order. A truncated or corrupt
/// file is an error naming it.
pub fn read_records(path: &Path, keep: &dyn Fn(&str) -> bool) -> Result<Vec<Record>, RecordingError> {
    let recording = Recording::open(path)?;
    let mut out = Vec::new();
    for m in recording.messages()? {
        let m = m?;
        if keep(m.topic()) {
            let (topic, log_time) = (m.topic().to_owned(), m.log_time());
            out.push(Record { topic, log_time, data: m.into_data() });
        }
    }
    Ok(out)
}

/// Compares the messages of `a` and `b` on the topics `keep` accepts.
pub fn compare(a: &Path, b: &Path, keep: &dyn Fn(&str) -> bool) -> Result<Comparison, RecordingError> {
    let (ra, rb) = (read_records(a, keep)?, read_records(b, keep)?);
    Ok(Comparison { messages: ra.len(), first_difference: first_difference(&ra, &rb) })
}

/// The first place where two message sequences differ, described for a person.
pub fn first_difference(a: &[Record], b: &[Record]) -> Option<Difference> {
    let at = |r: &Record| format!("`{}` at {:.3} s", r.topic, r.log_time as f64 / 1e9);
    for (index, (x, y)) in a.iter().zip(b).enumerate() {
        let detail = if x.topic != y.topic || x.log_time != y.log_time {
            format!("expected {}, found {}", at(x), at(y))
        } else if x.data != y.data {
            let byte = x
                .data
                .iter()
                .zip(&y.data)
                .position(|(p, q)| p != q)
                .unwrap_or(x.data.len().min(y.data.len()));
            format!(
                "{}: payloads differ from byte {byte} ({} vs {} bytes)",
                at(x),
                x.data.len(),
                y.data.len()
            )
        } else {
            continue;
        };
        return Some(Difference { index, detail });
    }
    let (n, m) = (a.len(), b.len());
    (n != m).then(|| {
        let (longer, which) = if n > m { (&a[m], "the first") } else { (&b[n], "the second") };
        Difference {
            index: n.min(m),
            detail: format!("{which} recording has {} more messages, from {}", n.abs_diff(m), at(longer)),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(topic: &str, t: u64, data: &[u8]) -> Record {
        Record { topic: topic.into(), log_time: t, data: data.to_vec() }
    }

    #[test]
    fn reports_the_first_difference_of_each_kind() {
        let a = vec![rec("odometry", 50_000_000, &[1, 2, 3]), rec("ums/map", 50_000_000, &[4])];
        assert_eq!(first_difference(&a, &a), None);
        let mut b = a.clone();
        b[1].data = vec![4, 0];
        let d = first_difference(&a, &b).expect("differs");
        assert_eq!(d.index, 1);
        assert_eq!(d.detail, "`ums/map` at 0.050 s: payloads differ from byte 1 (1 vs 2 bytes)");
        b = a.clone();
        b[0].log_time = 100_000_000;
        let d = first_difference(&a, &b).expect("differs");
        assert_eq!(
            (d.index, d.detail.as_str()),
            (0, "expected `odometry` at 0.050 s, found `odometry` at 0.100 s")
        );
        let d = first_difference(&a, &a[..1]).expect("shorter");
        assert_eq!(d.detail, "the first recording has 1 more messages, from `ums/map` at 0.050 s");
    }
}
