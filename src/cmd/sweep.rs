//! `harvey sweep MISSION --seeds A..B [--conditions NAME|FILE]… [--jobs N] [--out DIR]`: runs a
//! mission over seeds × sensor conditions in parallel `harvey run` processes, with a progress
//! bar, and writes `DIR/sweep.csv`, `DIR/sweep.md` and `DIR/sweep.png`.

mod conditions;
mod disk;
mod figures;
mod font;
mod plan;
mod plot;
mod report;
mod runner;

use std::path::{Path, PathBuf};

use conditions::Condition;
use figures::{Figure, Row, Stats};
use indicatif::{ProgressBar, ProgressStyle};
use plan::TempFiles;

use crate::summary::RunStats;

/// `harvey sweep`'s arguments.
#[derive(clap::Args)]
pub struct SweepArgs {
    /// The mission's launch file.
    pub mission: PathBuf,
    /// Seeds to run: `A..B`, both included (`1..20`), or one seed.
    #[arg(long)]
    pub seeds: String,
    /// A sensor condition: a name in conditions/ (nominal, dim, harsh) or a condition file (a
    /// TOML table of world overrides). Repeat, or separate by commas (default: nominal).
    #[arg(long = "conditions", value_name = "NAME|FILE", value_delimiter = ',')]
    pub conditions: Vec<String>,
    /// Runs at once (default: the available cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Output folder (default: recordings/sweep-<launch name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Keep the recordings of successful runs too (failed runs always keep theirs).
    #[arg(long)]
    pub keep: bool,
    /// Also draw each run's Rerun file (`run.rrd`, as large as its recording; without it,
    /// `harvey export RUN/run.mcap -o RUN/run.rrd` draws a kept run afterwards).
    #[arg(long)]
    pub rrd: bool,
    /// Bus prefix the runs' prefixes start with (default: sweep<pid>_).
    #[arg(long)]
    pub prefix: Option<String>,
    /// Run each mission in one process (`harvey run --in-process`: the same recording, no
    /// processes or shared memory, many times faster).
    #[arg(long)]
    pub in_process: bool,
}

/// A name safe as a folder name and in a bus prefix.
fn slug(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect()
}

fn read(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))
}

pub fn run(args: &SweepArgs) -> anyhow::Result<i32> {
    let seeds = plan::parse_seeds(&args.seeds)?;
    let lf = harvey_supervisor::LaunchFile::load(&args.mission)?;
    let launch_text = read(&args.mission)?;
    let launch: toml::Table = toml::from_str(&launch_text)?;
    let world_path =
        lf.world_path().ok_or_else(|| anyhow::anyhow!("{}: no [launch] world", args.mission.display()))?;
    let world_text = read(&world_path)?;
    let names = if args.conditions.is_empty() { vec!["nominal".to_owned()] } else { args.conditions.clone() };
    let mut conds: Vec<Condition> = Vec::new();
    for n in &names {
        let c = Condition::load(&conditions::resolve(n, &args.mission)?)?;
        if conds.iter().any(|d| d.name == c.name) {
            anyhow::bail!("argument `--conditions {n}`: condition `{}` is named twice", c.name);
        }
        conds.push(c);
    }
    let figure = Figure::for_mission(&launch, &toml::from_str(&world_text)?);
    let base = args.prefix.clone().unwrap_or_else(|| format!("sweep{}_", std::process::id()));
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("recordings").join(format!("sweep-{}", lf.settings.name)));

    // Each condition's merged world, checked, next to the mission; the launch copies name it.
    let mut temps = TempFiles::default();
    let mut worlds = Vec::new();
    for c in &conds {
        let merged = c.apply(&world_text, &world_path.display().to_string())?;
        if c.is_empty() {
            worlds.push(lf.settings.world.clone().unwrap_or_default());
            continue;
        }
        let p = plan::world_copy_path(&args.mission, &slug(&c.name));
        std::fs::write(&p, merged)?;
        worlds.push(PathBuf::from(p.file_name().unwrap_or_default()));
        temps.0.push(p);
    }
    std::fs::create_dir_all(out.join("runs"))?;
    let mut jobs = Vec::new();
    for &seed in &seeds {
        for (ci, c) in conds.iter().enumerate() {
            let tag = format!("{}-s{seed}", slug(&c.name));
            let prefix = format!("{base}c{ci}s{seed}_");
            harvey_bus::validate_prefix(&prefix)?;
            let launch = plan::launch_copy_path(&args.mission, &tag);
            temps.0.push(launch.clone());
            let launch_text = plan::launch_copy(&launch_text, seed, &worlds[ci], args.rrd)?;
            jobs.push(runner::Job {
                condition: ci,
                seed,
                launch,
                launch_text,
                run_dir: out.join("runs").join(&tag),
                prefix,
                in_process: args.in_process,
            });
        }
    }

    let cond_names: Vec<String> = conds.iter().map(|c| c.name.clone()).collect();
    let cond_files: Vec<(String, String)> =
        conds.iter().map(|c| (c.name.clone(), c.file.display().to_string())).collect();
    let header = report::Header {
        mission: &args.mission,
        name: &lf.settings.name,
        seeds: &args.seeds,
        conditions: &cond_files,
        figure,
        planned: jobs.len(),
    };
    let max = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from));
    let bar = ProgressBar::new(jobs.len() as u64);
    if let Ok(style) = ProgressStyle::with_template("{elapsed_precise} {wide_bar} {pos}/{len} runs  {msg}") {
        bar.set_style(style);
    }
    let say = |line: String| if bar.is_hidden() { eprintln!("{line}") } else { bar.println(line) };
    say(format!(
        "sweep: {} over {} seeds x {} conditions = {} runs, {max} at once, into {}",
        lf.settings.name,
        seeds.len(),
        conds.len(),
        jobs.len(),
        out.display()
    ));
    let interrupt = runner::interrupt_flag()?;
    let exe = std::env::current_exe()?;
    let mut rows: Vec<Row> = Vec::new();
    let mut order = Vec::new();
    let ending = runner::run_all(&exe, jobs, max, &out, &interrupt, |d| {
        let row = finish(d, &cond_names, figure, args.keep);
        // A failed run whose recording holds no mission status most often never started (a
        // mission or world file it could not read): its own error says why.
        let no_status = row.figures.as_ref().and_then(|f| f.state).is_none();
        let why = (no_status && !row.succeeded()).then(|| last_error(&row.log)).flatten();
        let why = why.map(|e| format!(" ({e})"));
        say(format!(
            "  {} s{}: {}, {}: {}{}",
            row.condition,
            row.seed,
            row.outcome(),
            figure.label(),
            row.figure.map_or("-".into(), |v| format!("{v:.2}")),
            why.unwrap_or_default()
        ));
        let key = (cond_names.iter().position(|n| *n == row.condition), row.seed);
        let at = order.partition_point(|k| *k < key);
        order.insert(at, key);
        rows.insert(at, row);
        bar.inc(1);
        bar.set_message(format!("{} failed", rows.iter().filter(|r| !r.succeeded()).count()));
        report::write(&out, &header, &rows)?;
        Ok(())
    })?;
    bar.finish_and_clear();
    drop(temps);
    report::write(&out, &header, &rows)?;
    plot::draw(
        &out.join("sweep.png"),
        &format!("harvey sweep: {}", lf.settings.name),
        figure,
        &cond_names,
        &rows,
    )?;
    for name in &cond_names {
        let s = Stats::of(rows.iter().filter(|r| &r.condition == name), figure);
        let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.2}"));
        println!(
            "{name}: {}/{} succeeded, {}: median {}, p90 {}, worst {}",
            s.successes,
            s.runs,
            figure.label(),
            f(s.median),
            f(s.p90),
            f(s.worst)
        );
    }
    let files = ["sweep.csv", "sweep.md", "sweep.png"].map(|f| out.join(f).display().to_string()).join(", ");
    if let Some(why) = &ending.short_of_disk {
        println!(
            "stopped short of disk: {why}; {} runs not started; the {} finished rows of {} are in {files}",
            ending.not_started,
            rows.len(),
            header.planned
        );
        return Ok(1);
    }
    if ending.interrupted {
        println!(
            "interrupted: stopped {} runs; the {} finished rows of {} are in {files}",
            ending.stopped.len(),
            rows.len(),
            header.planned
        );
        return Ok(130);
    }
    println!("wrote {files}");
    Ok(if rows.iter().all(Row::succeeded) { 0 } else { 1 })
}

/// The last line of a run's log that reports an error (`harvey: error: ...`), if any.
fn last_error(log: &Path) -> Option<String> {
    let text = std::fs::read_to_string(log).ok()?;
    let line = text.lines().rev().find(|l| l.starts_with("harvey: error:"))?;
    Some(line.trim().chars().take(300).collect())
}

/// A finished run's row: its figures read back from its recording, which is deleted when the
/// run succeeded (unless `keep`).
fn finish(d: runner::Done, conditions: &[String], figure: Figure, keep: bool) -> Row {
    let mcap = d.job.run_dir.join("run.mcap");
    let figures = if mcap.is_file() {
        match RunStats::read(&mcap) {
            Ok(s) => Some(s.figures()),
            Err(e) => {
                tracing::warn!("{}: {e:#}", mcap.display());
                None
            }
        }
    } else {
        None
    };
    let mut row = Row {
        condition: conditions.get(d.job.condition).cloned().unwrap_or_default(),
        seed: d.job.seed,
        exit_code: d.exit_code,
        figure: figures.as_ref().and_then(|f| figure.of(f)),
        figures,
        recording: mcap.is_file().then(|| mcap.clone()),
        log: d.log,
        wall_s: d.wall_s,
    };
    if row.succeeded() && !keep {
        let _ = std::fs::remove_file(&mcap);
        let _ = std::fs::remove_file(d.job.run_dir.join("run.rrd"));
        row.recording = None;
    }
    row
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]
    use super::*;

    #[test]
    fn a_run_s_last_error_line_is_what_the_sweep_names() {
        let dir = std::env::temp_dir().join(format!("harvey-sweep-last-error-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a directory");
        let log = dir.join("harvey-run.log");
        let text = "INFO camera mount misaligned\nharvey: error: first\nWARN a service: error: not this\nharvey: error: a.toml: key `x`: unknown field\nERROR another: error: nor this\n";
        std::fs::write(&log, text).expect("written");
        assert_eq!(last_error(&log).as_deref(), Some("harvey: error: a.toml: key `x`: unknown field"));
        std::fs::write(&log, "INFO all well\n").expect("written");
        assert_eq!(last_error(&log), None);
        assert_eq!(last_error(&dir.join("missing.log")), None);
        std::fs::remove_dir_all(&dir).expect("removed");
    }
}
