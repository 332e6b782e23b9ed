//! What a recording carries besides its messages: the launch file and world file of the run, the
//! data files the launch names, the world placed as the run placed it (by the seed of the
//! `harvey.world` record), and the recorder's per-topic counts.

use std::borrow::Cow;

use harvey_world::{Pole, World};

use crate::data_files::{DATA_MEDIA_TYPE, is_plain_relative};
use crate::summary::{Located, attachment, metadata};
use crate::{
    LAUNCH_MEDIA_TYPE, RECORDER_METADATA, Recording, RecordingError, WORLD_MEDIA_TYPE, WORLD_METADATA,
};

/// A data file a recording carries: its path relative to the launch file, and its bytes.
pub struct DataFile<'a> {
    pub name: String,
    pub data: Cow<'a, [u8]>,
}

impl Recording {
    /// The text of the first attachment of `media_type`; needs the summary section.
    fn attached_text(&self, media_type: &'static str) -> Result<String, RecordingError> {
        let summary = self.summary()?;
        let file = || self.path().to_owned();
        let index = summary
            .attachment_indexes
            .iter()
            .find(|a| a.media_type == media_type)
            .ok_or_else(|| RecordingError::NoAttachment { file: file(), media_type })?;
        let a = attachment(self.bytes(), index).map_err(|Located { offset, what }| {
            RecordingError::Attachment { file: file(), name: index.name.clone(), offset, what }
        })?;
        let text = std::str::from_utf8(&a.data).map_err(|cause| RecordingError::NotText {
            file: file(),
            name: a.name.clone(),
            cause,
        })?;
        Ok(text.to_owned())
    }

    /// The launch file of the run, as attached.
    pub fn launch_text(&self) -> Result<String, RecordingError> {
        self.attached_text(LAUNCH_MEDIA_TYPE)
    }

    /// The world file of the run, as attached.
    pub fn world_text(&self) -> Result<String, RecordingError> {
        self.attached_text(WORLD_MEDIA_TYPE)
    }

    /// The data files the launch named, in file order; each name is checked to stay inside the
    /// folder it is written back to (a recording must not make a replay write elsewhere).
    pub fn data_files(
        &self,
    ) -> Result<impl Iterator<Item = Result<DataFile<'_>, RecordingError>>, RecordingError> {
        let summary = self.summary()?;
        let indexes = summary.attachment_indexes.iter().filter(|a| a.media_type == DATA_MEDIA_TYPE);
        Ok(indexes.map(|index| {
            let (file, name) = (self.path().to_owned(), index.name.clone());
            if !is_plain_relative(&name) {
                return Err(RecordingError::DataName { file, name });
            }
            match attachment(self.bytes(), index) {
                Ok(a) => Ok(DataFile { name, data: a.data }),
                Err(Located { offset, what }) => Err(RecordingError::Attachment { file, name, offset, what }),
            }
        }))
    }

    /// The world the recording carries, with its `[poles]` placed by the recorded seed (1 when
    /// the recording predates the `harvey.world` record, as the recorder's default), and those
    /// poles; `None` without a world attachment (or when the footer says there is no summary to
    /// find it by). A summary that does not read (or no footer: a writer killed), a data section
    /// whose CRC does not check (what vouches for the seed's metadata record) and a world
    /// attachment that does not load are errors naming them.
    pub fn world(&self) -> Result<Option<(World, Vec<Pole>)>, RecordingError> {
        let Some(summary) = self.summary_state()? else { return Ok(None) };
        let Some(index) = summary.attachment_indexes.iter().find(|a| a.media_type == WORLD_MEDIA_TYPE) else {
            return Ok(None);
        };
        let file = || self.path().to_owned();
        let att = attachment(self.bytes(), index).map_err(|Located { offset, what }| {
            RecordingError::Attachment { file: file(), name: index.name.clone(), offset, what }
        })?;
        let text = std::str::from_utf8(&att.data).map_err(|cause| RecordingError::NotText {
            file: file(),
            name: att.name.clone(),
            cause,
        })?;
        let mut world = harvey_world::load_str(text, &att.name)
            .map_err(|cause| RecordingError::World { file: file(), cause })?;
        let mut seed = 1;
        if let Some(m) = summary.metadata_indexes.iter().find(|m| m.name == WORLD_METADATA) {
            self.check_data_section()?;
            let record = metadata(self.bytes(), m).map_err(|Located { offset, what }| {
                RecordingError::Metadata { file: file(), name: WORLD_METADATA, offset, what }
            })?;
            if let Some(text) = record.metadata.get("seed") {
                seed = text.parse().map_err(|cause| RecordingError::Seed {
                    file: file(),
                    text: text.clone(),
                    cause,
                })?;
            }
        }
        let poles = world.place_poles(seed).map_err(|cause| RecordingError::Poles {
            file: file(),
            name: att.name.clone(),
            cause,
        })?;
        Ok(Some((world, poles)))
    }

    /// The sequence numbers the recorder saw skipped, per topic, from its `harvey.recorder`
    /// records in file order (`None` where a count does not parse); nothing when the footer says
    /// there is no summary, an error when there is none that reads (as [`Recording::world`]).
    /// Metadata has no CRC of its own: it is read only once the data section's CRC checks.
    pub fn seq_gaps(&self) -> Result<Vec<(String, Option<u64>)>, RecordingError> {
        let Some(summary) = self.summary_state()? else { return Ok(Vec::new()) };
        let mut gaps = Vec::new();
        for idx in summary.metadata_indexes.iter().filter(|i| i.name == RECORDER_METADATA) {
            self.check_data_section()?;
            let md =
                metadata(self.bytes(), idx).map_err(|Located { offset, what }| RecordingError::Metadata {
                    file: self.path().to_owned(),
                    name: RECORDER_METADATA,
                    offset,
                    what,
                })?;
            for (k, v) in &md.metadata {
                if let Some(topic) = k.strip_suffix(".seq_gaps") {
                    gaps.push((topic.to_owned(), v.parse().ok()));
                }
            }
        }
        Ok(gaps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recorder;

    const ARENA: &str = include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../../worlds/arena.toml"));

    /// A recording of nothing but `world` placed by `seed`, and what `more` attaches.
    fn recording(name: &str, world: &str, seed: u64, more: impl FnOnce(&mut Recorder)) -> Recording {
        let dir = std::env::temp_dir().join(format!("harvey-attach-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let path = dir.join("t.mcap");
        let mut r = Recorder::create(&path).expect("create");
        r.attach_world("arena.toml", world, seed).expect("attach");
        more(&mut r);
        r.finish().expect("finish");
        let recording = Recording::open(&path).expect("read");
        std::fs::remove_dir_all(&dir).ok();
        recording
    }

    fn walls(w: &World) -> Vec<[[f64; 2]; 2]> {
        w.walls.iter().map(|w| [w.from, w.to]).collect()
    }

    #[test]
    fn the_world_comes_back_with_the_poles_where_the_recorded_seed_put_them() {
        for seed in [3, 4] {
            let r = recording(&format!("s{seed}"), ARENA, seed, |_| {});
            let (got, placed) = r.world().expect("loads").expect("a world");
            let mut want = harvey_world::load_str(ARENA, "arena.toml").expect("arena");
            let bare = want.walls.len();
            let poles = want.place_poles(seed).expect("placed");
            assert_eq!((poles.len(), &placed), (10, &poles));
            assert!(want.walls.len() > bare, "poles are walls");
            assert_eq!(walls(&got), walls(&want), "seed {seed}");
        }
        let (a, b) = (recording("a", ARENA, 3, |_| {}), recording("b", ARENA, 4, |_| {}));
        let world = |r: &Recording| walls(&r.world().expect("loads").expect("a world").0);
        assert_ne!(world(&a), world(&b), "another seed, other places");
    }

    #[test]
    fn a_world_attachment_that_does_not_load_is_named() {
        let r = recording("bad", "[[wall]]\nfrom = \"here\"\n", 1, |_| {});
        let e = r.world().expect_err("malformed world").to_string();
        assert!(e.contains("world attachment") && e.contains("arena.toml"), "{e}");
    }

    #[test]
    fn the_launch_and_its_data_files_come_back_and_names_that_escape_are_refused() {
        let r = recording("launch", ARENA, 1, |r| {
            r.attach_launch("d.toml", "[launch]\nname = \"d\"\n").expect("launch");
            r.attach_data("fsa/docking.toml", b"q0").expect("data");
            r.attach_data("../up.toml", b"x").expect("data");
        });
        assert_eq!(r.launch_text().expect("launch"), "[launch]\nname = \"d\"\n");
        assert_eq!(r.world_text().expect("world"), ARENA);
        let files: Vec<_> = r.data_files().expect("summary").collect();
        let first = files[0].as_ref().expect("plain");
        assert_eq!((first.name.as_str(), &first.data[..]), ("fsa/docking.toml", &b"q0"[..]));
        let e = files[1].as_ref().err().expect("escapes").to_string();
        assert!(e.contains("data attachment `../up.toml`"), "{e}");
        let bare = recording("bare", ARENA, 1, |_| {});
        let e = bare.launch_text().expect_err("no launch").to_string();
        assert!(
            e.ends_with("no `application/toml; harvey-launch` attachment: was it recorded by `harvey run`?")
        );
    }
}
