//! A service's inputs, tick by tick, in an append-only file: for a service whose state is too
//! rich to checkpoint (the executive's plans, scripts and behaviours), a restarted process is
//! rebuilt by running its inputs through it again, its outputs discarded. The logic is
//! deterministic, so it arrives where its predecessor was.
//!
//! `$HARVEY_STATE_DIR/<service>.journal` holds records of `[length u32][CRC-32 u32][postcard]`.
//! Opening reads the records whose CRC checks up to the first that does not (a record cut short
//! by SIGKILL), and cuts the file there, so the next append follows the last good record.

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::checkpoint::{CheckpointError, STATE_DIR_ENV};

/// The longest record a journal takes (a tick's inputs).
pub const MAX_RECORD: usize = 16 << 20;

/// An open journal.
pub struct Journal {
    path: PathBuf,
    file: File,
    scratch: Vec<u8>,
}

impl Journal {
    /// The journal of `service` in the supervisor's state folder, with the records it already
    /// holds; `None` for a service started by hand.
    pub fn from_env<T: DeserializeOwned>(service: &str) -> Result<Option<(Self, Vec<T>)>, CheckpointError> {
        match std::env::var_os(STATE_DIR_ENV) {
            Some(dir) => Self::open(&Path::new(&dir).join(format!("{service}.journal"))).map(Some),
            None => Ok(None),
        }
    }

    /// Opens (or creates) a journal and reads its good records.
    pub fn open<T: DeserializeOwned>(path: &Path) -> Result<(Self, Vec<T>), CheckpointError> {
        let io = |source| CheckpointError::Io { path: path.to_owned(), source };
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .mode(0o600)
            .open(path)
            .map_err(io)?;
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).map_err(io)?;
        let (mut records, mut at) = (Vec::new(), 0usize);
        while let Some(head) = bytes.get(at..at + 8) {
            let len = u32::from_le_bytes([head[0], head[1], head[2], head[3]]) as usize;
            let crc = u32::from_le_bytes([head[4], head[5], head[6], head[7]]);
            let Some(body) =
                bytes.get(at + 8..at + 8 + len).filter(|b| len <= MAX_RECORD && crc32fast::hash(b) == crc)
            else {
                break;
            };
            let Ok(record) = postcard::from_bytes(body) else { break };
            records.push(record);
            at += 8 + len;
        }
        if at < bytes.len() {
            tracing::warn!(path = %path.display(), kept = records.len(), dropped_bytes = bytes.len() - at, "journal: a record cut short is dropped");
        }
        file.set_len(at as u64).map_err(io)?;
        let mut j = Self { path: path.to_owned(), file, scratch: Vec::new() };
        j.seek_end()?;
        Ok((j, records))
    }

    fn seek_end(&mut self) -> Result<(), CheckpointError> {
        use std::io::Seek;
        self.file
            .seek(std::io::SeekFrom::End(0))
            .map(drop)
            .map_err(|source| CheckpointError::Io { path: self.path.clone(), source })
    }

    /// Appends one record (in one write, so a kill leaves it whole or cut short, never mixed).
    pub fn append<T: Serialize>(&mut self, record: &T) -> Result<(), CheckpointError> {
        self.scratch.clear();
        self.scratch.extend_from_slice(&[0; 8]);
        self.scratch = postcard::to_extend(record, std::mem::take(&mut self.scratch)).map_err(|e| {
            CheckpointError::Encoding { path: self.path.clone(), what: format!("writing a record: {e}") }
        })?;
        let len = self.scratch.len() - 8;
        if len > MAX_RECORD {
            return Err(CheckpointError::TooBig { path: self.path.clone(), len, cap: MAX_RECORD });
        }
        let crc = crc32fast::hash(&self.scratch[8..]);
        self.scratch[0..4].copy_from_slice(&(len as u32).to_le_bytes());
        self.scratch[4..8].copy_from_slice(&crc.to_le_bytes());
        self.file
            .write_all(&self.scratch)
            .map_err(|source| CheckpointError::Io { path: self.path.clone(), source })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_come_back_in_order_and_a_torn_one_is_cut_off() {
        let dir = std::env::temp_dir().join(format!("harvey-journal-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("j.journal");
        let _ = std::fs::remove_file(&path);
        let (mut j, old) = Journal::open::<(u64, Vec<f64>)>(&path).unwrap();
        assert!(old.is_empty());
        for t in 0..5u64 {
            j.append(&(t, vec![t as f64 * 0.1; t as usize])).unwrap();
        }
        drop(j);
        // A kill in the middle of the sixth record's write.
        let whole = std::fs::metadata(&path).unwrap().len();
        let mut f = OpenOptions::new().append(true).open(&path).unwrap();
        f.write_all(&[40, 0, 0, 0, 1, 2, 3, 4, 9, 9]).unwrap();
        drop(f);
        let (mut j, back) = Journal::open::<(u64, Vec<f64>)>(&path).unwrap();
        assert_eq!(back.len(), 5);
        assert_eq!(back[3], (3, vec![0.30000000000000004; 3]));
        assert_eq!(std::fs::metadata(&path).unwrap().len(), whole, "cut back to the last good record");
        j.append(&(5u64, Vec::<f64>::new())).unwrap();
        let (_, again) = Journal::open::<(u64, Vec<f64>)>(&path).unwrap();
        assert_eq!(again.len(), 6);
        assert_eq!(again[5], (5, vec![]));
    }
}
