//! The launch `harvey replay` runs: a recording carries its launch, world and data files, and
//! the replay launch is that launch with the input producers (simulated DRV, bridge, camera)
//! replaced by `harvey-replayer` as clock master.

use std::path::{Path, PathBuf};

use anyhow::Context;
use harvey_recording::Recording;
use harvey_recording::ticks::INPUT_SERVICES;

/// Name of the replay launch file written into the run folder.
pub const LAUNCH_FILE: &str = "replay.toml";

/// Writes the replay's launch and world files into `run_dir`; returns the launch file's path.
/// Unless `trust`, a launch that would start anything but Harvey's own service binaries is
/// refused before a file is written.
pub fn prepare(recording: &Path, run_dir: &Path, rrd: bool, trust: bool) -> anyhow::Result<PathBuf> {
    let name = recording.display().to_string();
    let rec = Recording::open(recording)?;
    let (world, launch) = (rec.world_text()?, rec.launch_text()?);
    let text =
        replay_launch(&launch, recording, rrd).with_context(|| format!("{name}: attached launch file"))?;
    let foreign = foreign_binaries(&text)?;
    anyhow::ensure!(
        trust || foreign.is_empty(),
        "{name}: its launch file would start {}, not Harvey's own service binaries; replay it only \
         if you trust the recording (--trust-recording)",
        foreign.join(", ")
    );
    std::fs::create_dir_all(run_dir).with_context(|| format!("creating {}", run_dir.display()))?;
    let original = std::fs::canonicalize(recording).with_context(|| format!("resolving {name}"))?;
    let output = std::fs::canonicalize(run_dir)?.join("run.mcap");
    anyhow::ensure!(output != original, "the replay would overwrite {name}: choose another --run-dir");
    std::fs::write(run_dir.join("world.toml"), world)?;
    // The launch's data files (acceptor tables...), back beside the replay's launch file.
    for file in rec.data_files()? {
        let file = file?;
        let to = run_dir.join(&file.name);
        if let Some(dir) = to.parent() {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        std::fs::write(&to, &file.data).with_context(|| format!("writing {}", to.display()))?;
    }
    let text =
        replay_launch(&launch, &original, rrd).with_context(|| format!("{name}: attached launch file"))?;
    let path = run_dir.join(LAUNCH_FILE);
    std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}

/// A `[[service]]` table's binary: its `binary`, else `harvey-<name>` (as the supervisor's
/// `Service::binary` reads it from the typed file).
pub(super) fn binary_of(s: &toml::Value) -> String {
    let name = s.get("name").and_then(|n| n.as_str()).unwrap_or_default();
    s.get("binary").and_then(|b| b.as_str()).map_or(format!("harvey-{name}"), str::to_owned)
}

/// The services of launch text `text` whose binary is not one of Harvey's own (named
/// `harvey-<something>` and found beside the CLI or on the PATH, no path given), as
/// `service (binary)`.
pub fn foreign_binaries(text: &str) -> anyhow::Result<Vec<String>> {
    let doc: toml::Table = text.parse()?;
    let services = doc.get("service").and_then(|s| s.as_array()).map(Vec::as_slice).unwrap_or_default();
    Ok(services
        .iter()
        .filter_map(|s| {
            let name = s.get("name").and_then(|n| n.as_str()).unwrap_or_default();
            let binary = binary_of(s);
            let own = binary.starts_with("harvey-")
                && binary.len() > "harvey-".len()
                && binary.chars().all(|c| c.is_ascii_alphanumeric() || c == '-');
            (!own).then(|| format!("{name} ({binary})"))
        })
        .collect())
}

/// The launch file of a replay of `recording`, from the launch file that recorded it. Without
/// `rrd`, the recorder loses its `--rrd FILE`: a replay checks and records the MCAP, and
/// `harvey export` draws it when wanted; with it, the recorder draws `run.rrd` in the run folder
/// whether or not the recording's did.
pub fn replay_launch(text: &str, recording: &Path, rrd: bool) -> anyhow::Result<String> {
    let mut doc: toml::Table = text.parse()?;
    let launch = doc.get_mut("launch").and_then(|l| l.as_table_mut()).context("no [launch] table")?;
    let name = launch.get("name").and_then(|n| n.as_str()).unwrap_or("run").to_owned();
    launch.insert("name".into(), format!("{name}-replay").into());
    launch.insert("world".into(), "world.toml".into());
    launch.insert("end_with".into(), "replayer".into());
    launch.insert("clock".into(), "lockstep".into());
    launch.insert("clock_master".into(), "replayer".into());
    let services = doc.get_mut("service").and_then(|s| s.as_array_mut()).context("no [[service]]")?;
    let is_input = |s: &toml::Value| INPUT_SERVICES.contains(&binary_of(s).as_str());
    let at =
        services.iter().position(is_input).context("no input service (simulated DRV, bridge, camera)")?;
    services.retain(|s| !is_input(s));
    // A sweep's runs were recorded without a Rerun file: asked for, the replay draws one.
    match rrd {
        true => super::rrd_arg::ensure_rrd(services, "${run_dir}/run.rrd"),
        false => super::rrd_arg::drop_rrd(services),
    }
    let mut replayer = toml::Table::new();
    replayer.insert("name".into(), "replayer".into());
    replayer.insert("args".into(), vec!["--recording".to_owned(), recording.display().to_string()].into());
    replayer.insert("restart".into(), "never".into());
    services.insert(at, replayer.into());
    Ok(toml::to_string(&doc)?)
}

#[cfg(test)]
mod trust_tests {
    use super::foreign_binaries;

    #[test]
    fn only_harvey_service_binaries_are_trusted() {
        let own = "[launch]\nname = \"x\"\n[[service]]\nname = \"ums\"\n[[service]]\nname = \"r\"\nbinary = \"harvey-recorder\"\n";
        assert!(foreign_binaries(own).expect("parses").is_empty());
        for bad in ["/bin/sh", "sh", "harvey-", "../harvey-ums", "harvey-ums; rm", "/usr/bin/harvey-ums"] {
            let text = format!("[launch]\nname = \"x\"\n[[service]]\nname = \"evil\"\nbinary = \"{bad}\"\n");
            assert_eq!(foreign_binaries(&text).expect("parses"), [format!("evil ({bad})")], "{bad}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_input_services_give_way_to_the_replayer() {
        let text = std::fs::read_to_string("missions/default.toml").expect("default mission");
        let out = replay_launch(&text, Path::new("/r/run.mcap"), false).expect("rewrites");
        let lf = harvey_supervisor::LaunchFile::parse(&out, Path::new("replay.toml"))
            .expect("a valid launch file");
        let names: Vec<&str> = lf.services.iter().map(|s| s.name()).collect();
        assert_eq!(
            names,
            ["recorder", "replayer", "sonar", "encoders", "vision-workers", "ums", "executive"]
        );
        assert_eq!(lf.clock_chain()[0], "replayer");
        assert_eq!(lf.clock_chain().last().map(String::as_str), Some("recorder"));
        assert_eq!(lf.services[1].args, ["--recording", "/r/run.mcap"]);
        assert!(out.contains("[mission]") && out.contains("move_m = 4.0"), "the mission travels along");
        assert!(!lf.services[0].args.iter().any(|a| a == "--rrd"), "no Rerun file unless asked");
        let with_rrd = replay_launch(&text, Path::new("/r/run.mcap"), true).expect("rewrites");
        assert!(with_rrd.contains("--rrd"));
        assert!(
            replay_launch("[launch]\nname = \"x\"\n[[service]]\nname = \"ums\"\n", Path::new("r"), false)
                .is_err()
        );
    }
}
