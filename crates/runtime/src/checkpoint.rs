//! A service's state saved at tick boundaries, so that a restarted process picks up where its
//! killed predecessor left off (the robot's physics, a bridge's place in the clock chain).
//!
//! The supervisor gives every child `$HARVEY_STATE_DIR` (a folder of the run, emptied when the
//! launch starts); a service's checkpoint is `<dir>/<service>.ckpt`. The file holds two slots;
//! each save writes the slot the previous save did not, with a generation number and a CRC, so a
//! save cut short by SIGKILL leaves the one before it intact, and a load takes the newest slot
//! whose CRC checks. States are serialised with `postcard` (exact for floats and 64-bit
//! integers).

use std::fs::{File, OpenOptions};
use std::os::unix::fs::{FileExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

use serde::Serialize;
use serde::de::DeserializeOwned;

/// The folder the supervisor keeps its children's checkpoints in.
pub const STATE_DIR_ENV: &str = "HARVEY_STATE_DIR";

const MAGIC: &[u8; 4] = b"HVCK";
const VERSION: u32 = 1;
/// magic, version, generation, payload length, CRC.
const HEADER: usize = 4 + 4 + 8 + 4 + 4;

/// Why a checkpoint could not be used.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("checkpoint {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("checkpoint {}: a state of {len} bytes does not fit a slot of {cap}", path.display())]
    TooBig { path: PathBuf, len: usize, cap: usize },
    #[error("checkpoint {}: {what}", path.display())]
    Encoding { path: PathBuf, what: String },
}

/// One service's checkpoint file.
pub struct Checkpoint {
    path: PathBuf,
    file: File,
    slot_bytes: usize,
    generation: u64,
    scratch: Vec<u8>,
}

impl Checkpoint {
    /// The checkpoint of `service` in the supervisor's state folder, if there is one (a service
    /// started by hand keeps none). `slot_bytes` bounds the state's size.
    pub fn from_env(service: &str, slot_bytes: usize) -> Result<Option<Self>, CheckpointError> {
        match std::env::var_os(STATE_DIR_ENV) {
            Some(dir) => Self::open(&Path::new(&dir).join(format!("{service}.ckpt")), slot_bytes).map(Some),
            None => Ok(None),
        }
    }

    /// Opens (or creates) a checkpoint file.
    pub fn open(path: &Path, slot_bytes: usize) -> Result<Self, CheckpointError> {
        let io = |source| CheckpointError::Io { path: path.to_owned(), source };
        let file =
            // Owner only, as the bus's shared memory is.
            OpenOptions::new().read(true).write(true).create(true).truncate(false).mode(0o600).open(path).map_err(io)?;
        let mut ck = Self {
            path: path.to_owned(),
            file,
            slot_bytes: slot_bytes.max(HEADER + 1),
            generation: 0,
            scratch: Vec::new(),
        };
        ck.generation = ck.newest()?.map_or(0, |(g, _)| g);
        Ok(ck)
    }

    /// The newest state saved, if any slot holds one whose CRC checks.
    pub fn load<T: DeserializeOwned>(&mut self) -> Result<Option<T>, CheckpointError> {
        let Some((_, bytes)) = self.newest()? else { return Ok(None) };
        postcard::from_bytes(&bytes).map(Some).map_err(|e| CheckpointError::Encoding {
            path: self.path.clone(),
            what: format!("reading the state: {e}"),
        })
    }

    /// Saves `state` over the older slot.
    pub fn save<T: Serialize>(&mut self, state: &T) -> Result<(), CheckpointError> {
        let generation = self.generation + 1;
        self.scratch.clear();
        self.scratch.extend_from_slice(&[0; HEADER]);
        self.scratch = postcard::to_extend(state, std::mem::take(&mut self.scratch)).map_err(|e| {
            CheckpointError::Encoding { path: self.path.clone(), what: format!("writing the state: {e}") }
        })?;
        let len = self.scratch.len() - HEADER;
        if self.scratch.len() > self.slot_bytes {
            return Err(CheckpointError::TooBig {
                path: self.path.clone(),
                len,
                cap: self.slot_bytes - HEADER,
            });
        }
        let len32 = len as u32;
        let crc = crc(generation, len32, &self.scratch[HEADER..]);
        self.scratch[0..4].copy_from_slice(MAGIC);
        self.scratch[4..8].copy_from_slice(&VERSION.to_le_bytes());
        self.scratch[8..16].copy_from_slice(&generation.to_le_bytes());
        self.scratch[16..20].copy_from_slice(&len32.to_le_bytes());
        self.scratch[20..24].copy_from_slice(&crc.to_le_bytes());
        let at = (generation % 2) * self.slot_bytes as u64;
        self.file
            .write_all_at(&self.scratch, at)
            .map_err(|source| CheckpointError::Io { path: self.path.clone(), source })?;
        self.generation = generation;
        Ok(())
    }

    /// The valid slot with the highest generation.
    fn newest(&self) -> Result<Option<(u64, Vec<u8>)>, CheckpointError> {
        let mut best: Option<(u64, Vec<u8>)> = None;
        for slot in 0..2u64 {
            if let Some((g, bytes)) = self.read_slot(slot * self.slot_bytes as u64)?
                && best.as_ref().is_none_or(|(b, _)| g > *b)
            {
                best = Some((g, bytes));
            }
        }
        Ok(best)
    }

    fn read_slot(&self, at: u64) -> Result<Option<(u64, Vec<u8>)>, CheckpointError> {
        let io = |source| CheckpointError::Io { path: self.path.clone(), source };
        let mut head = [0u8; HEADER];
        match self.file.read_exact_at(&mut head, at) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
            Err(e) => return Err(io(e)),
        }
        let word =
            |r: core::ops::Range<usize>| head[r].iter().rev().fold(0u64, |acc, b| acc << 8 | u64::from(*b));
        if &head[0..4] != MAGIC || word(4..8) != u64::from(VERSION) {
            return Ok(None);
        }
        let (generation, len, crc_read) = (word(8..16), word(16..20) as usize, word(20..24) as u32);
        if len + HEADER > self.slot_bytes {
            return Ok(None);
        }
        let mut bytes = vec![0; len];
        match self.file.read_exact_at(&mut bytes, at + HEADER as u64) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
            Err(e) => return Err(io(e)),
        }
        Ok((crc(generation, len as u32, &bytes) == crc_read).then_some((generation, bytes)))
    }
}

fn crc(generation: u64, len: u32, payload: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(&generation.to_le_bytes());
    h.update(&len.to_le_bytes());
    h.update(payload);
    h.finalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("harvey-ckpt-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join("s.ckpt")
    }

    #[test]
    fn the_newest_state_comes_back_exactly() {
        let path = scratch("newest");
        let _ = std::fs::remove_file(&path);
        let mut ck = Checkpoint::open(&path, 4096).unwrap();
        assert_eq!(ck.load::<(u64, f64)>().unwrap(), None);
        for i in 0..5u64 {
            ck.save(&(u64::MAX - i, 0.1 + i as f64)).unwrap();
        }
        let mut again = Checkpoint::open(&path, 4096).unwrap();
        assert_eq!(again.load::<(u64, f64)>().unwrap(), Some((u64::MAX - 4, 4.1)));
        // It goes on numbering from the file's generation.
        again.save(&(7u64, 7.0)).unwrap();
        assert_eq!(Checkpoint::open(&path, 4096).unwrap().load::<(u64, f64)>().unwrap(), Some((7, 7.0)));
    }

    #[test]
    fn a_torn_save_leaves_the_one_before() {
        let path = scratch("torn");
        let _ = std::fs::remove_file(&path);
        let mut ck = Checkpoint::open(&path, 256).unwrap();
        ck.save(&vec![1u32; 8]).unwrap();
        ck.save(&vec![2u32; 8]).unwrap();
        // Damage the newer slot's payload (generation 2 sits in slot 0).
        let f = OpenOptions::new().write(true).open(&path).unwrap();
        f.write_all_at(&[0xff], HEADER as u64 + 3).unwrap();
        assert_eq!(Checkpoint::open(&path, 256).unwrap().load::<Vec<u32>>().unwrap(), Some(vec![1; 8]));
    }

    #[test]
    fn a_state_too_big_for_its_slot_is_refused_and_the_file_kept() {
        let path = scratch("big");
        let _ = std::fs::remove_file(&path);
        let mut ck = Checkpoint::open(&path, 64).unwrap();
        ck.save(&3u8).unwrap();
        let err = ck.save(&vec![9u8; 100]).unwrap_err();
        assert!(err.to_string().contains("does not fit"), "{err}");
        assert_eq!(ck.load::<u8>().unwrap(), Some(3));
    }
}
