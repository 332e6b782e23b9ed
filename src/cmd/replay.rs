//! `harvey replay RECORDING [--check]`: run a recording's services again on its recorded inputs
//! and record them again; `--check` compares the new recording with the old.

use std::path::{Path, PathBuf};

use harvey_recording::Recording;
use harvey_recording::same_file::same_file;

use super::replay_launch::{LAUNCH_FILE, prepare};
use super::{LaunchArgs, launch_file, report_comparison};

/// The files a replay writes into its run folder besides the data files the recording carries:
/// the new recording and Rerun file (as the launches name them), the world and the launch.
const WRITTEN: [&str; 4] = ["run.mcap", "run.rrd", "world.toml", LAUNCH_FILE];

/// How a replay runs.
pub struct How {
    /// Compare the new recording with the old.
    pub check: bool,
    /// Draw the new recording into a Rerun file.
    pub rrd: bool,
    /// Start whatever binaries the recording's launch file names (`--trust-recording`); without
    /// it only Harvey's own service binaries.
    pub trust: bool,
    /// Run the services as nodes of this process instead of processes over shared memory.
    pub in_process: bool,
}

pub fn run(recording: &Path, how: How, opts: LaunchArgs) -> anyhow::Result<i32> {
    // Every argument is checked before anything is written.
    harvey_bus::validate_prefix(&opts.prefix)?;
    anyhow::ensure!(
        !opts.realtime,
        "--realtime: a replay is deterministic (the replayer hands the services each recorded tick in turn)"
    );
    let run_dir =
        opts.run_dir.clone().unwrap_or_else(|| recording.parent().unwrap_or(Path::new(".")).join("replay"));
    refuse_writing_over(recording, &run_dir)?;
    refuse_other_messages(recording)?;
    // A live view is drawn from the Rerun file's stream.
    let file = prepare(recording, &run_dir, how.rrd || opts.live.is_some(), how.trust)?;
    let again = run_dir.join("run.mcap");
    if how.in_process {
        println!("replaying in process: {} (the launch {} carries)", file.display(), recording.display());
        let r = super::inproc::replay(recording, &file, &run_dir)?;
        println!(
            "replay: {} ticks, {} messages, {:.2} s of the run in {:.3} s: {:.1}x real time",
            r.ticks,
            r.messages,
            r.sim_s,
            r.wall_s,
            r.sim_s / r.wall_s.max(1e-9)
        );
        println!("{}", super::inproc::turns_line(&r.turns));
        if r.left_out > 0 {
            println!("left out: {} messages stamped after the tick they came in", r.left_out);
        }
    } else {
        println!("replaying: {} (the launch {} carries)", file.display(), recording.display());
        let (outcome, _) = launch_file(&file, &LaunchArgs { run_dir: Some(run_dir.clone()), ..opts })?;
        println!("replay: {outcome:?}");
        if outcome.exit_code() != 0 {
            println!("recording: {}", again.display());
            return Ok(outcome.exit_code());
        }
    }
    println!("recording: {}", again.display());
    if !how.check {
        return Ok(0);
    }
    let c = harvey_recording::compare::compare(recording, &again, &|_| true)?;
    Ok(report_comparison(&c, recording, &again))
}

/// An error, before anything is written, when the recording's messages are laid out otherwise
/// than this build's: replayed, they would be read into a wrong answer.
fn refuse_other_messages(recording: &Path) -> anyhow::Result<()> {
    let differences = harvey_recording::schemas::differences(&Recording::open(recording)?)?;
    anyhow::ensure!(
        differences.is_empty(),
        "{}: its messages are not this build's ({}): replay it with the Harvey that recorded it",
        recording.display(),
        differences.join("; ")
    );
    Ok(())
}

/// An error, before anything is written, when the recording is one of the files the replay would
/// write into `run_dir` (by any name: a symlink, a hard link).
fn refuse_writing_over(recording: &Path, run_dir: &Path) -> anyhow::Result<()> {
    // Nothing in a folder that does not exist yet can be the recording.
    if !run_dir.is_dir() {
        return Ok(());
    }
    let mut written: Vec<PathBuf> = WRITTEN.iter().map(|name| run_dir.join(name)).collect();
    // The data files' names are checked (and refused when they escape) by `prepare`.
    let rec = Recording::open(recording)?;
    if let Ok(files) = rec.data_files() {
        written.extend(files.flatten().map(|f| run_dir.join(f.name)));
    }
    if let Some(file) = written.iter().find(|file| same_file(recording, file)) {
        anyhow::bail!(
            "the replay would overwrite {} (as {}): choose another --run-dir",
            recording.display(),
            file.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_recording_that_would_start_a_foreign_binary_is_refused_before_anything_is_written() {
        let dir = std::env::temp_dir().join(format!("harvey-replay-trust-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let recording = dir.join("crafted.mcap");
        let mut r = harvey_recording::Recorder::create(&recording).expect("create");
        let launch = "[launch]\nname = \"l\"\nend_with = \"ums\"\n[[service]]\nname = \"sim-drv\"\n\
                      [[service]]\nname = \"ums\"\nbinary = \"/bin/sh\"\nargs = [\"-c\", \"true\"]\n";
        r.attach_launch("l.toml", launch).expect("launch");
        r.attach_world("w.toml", "name = \"w\"\n", 1).expect("world");
        r.finish().expect("finish");
        let run_dir = dir.join("replay");
        let e = prepare(&recording, &run_dir, false, false).expect_err("refused").to_string();
        assert!(e.contains("ums (/bin/sh)") && e.contains("--trust-recording"), "{e}");
        assert!(!run_dir.exists(), "nothing is written for a refused replay");
        let opts = LaunchArgs {
            run_dir: Some(dir.join("other")),
            prefix: "bad prefix".into(),
            realtime: false,
            live: None,
            foxglove: None,
            zenoh_listen: Vec::new(),
            zenoh_connect: Vec::new(),
            host: None,
            ros2_domain: None,
        };
        let how = How { check: false, rrd: false, trust: false, in_process: false };
        assert!(run(&recording, how, opts).is_err(), "a bad prefix is refused");
        assert!(!dir.join("other").exists(), "before anything is written");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_replay_never_writes_into_the_recording_it_replays() {
        let dir = std::env::temp_dir().join(format!("harvey-replay-over-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("fsa")).expect("tmp");
        let recording = dir.join("source.mcap");
        let mut r = harvey_recording::Recorder::create(&recording).expect("create");
        r.attach_launch("l.toml", "[launch]\nname = \"l\"\nfiles = [\"fsa/t.toml\"]\n").expect("launch");
        r.attach_data("fsa/t.toml", b"x").expect("data");
        r.finish().expect("finish");
        assert!(refuse_writing_over(&recording, &dir.join("elsewhere")).is_ok(), "no such folder yet");
        assert!(refuse_writing_over(&recording, &dir).is_ok(), "source.mcap is not written");
        for (name, written) in
            [("run.mcap", "run.mcap"), ("world.toml", "world.toml"), ("fsa/t.toml", "fsa/t.toml")]
        {
            std::os::unix::fs::symlink(&recording, dir.join(name)).expect("link");
            let e = refuse_writing_over(&recording, &dir).expect_err(name).to_string();
            assert!(
                e.contains("would overwrite")
                    && e.ends_with(&format!("{written}): choose another --run-dir")),
                "{e}"
            );
            std::fs::remove_file(dir.join(name)).expect("unlink");
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}
