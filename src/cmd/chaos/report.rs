//! The chaos harness's figures: each killed run judged against the reference recording, and
//! the table (per service: kills, missions that reached their goal, time gone p50/p99,
//! recordings identical, messages missing) with the machine it ran on.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::time::Duration;

use harvey_recording::compare::{Record, read_records};

/// One SIGKILL.
#[derive(Debug, Clone)]
pub struct Kill {
    pub service: String,
    /// Simulated time of the kill (s).
    pub at_s: f64,
    /// Kill to the successor on the bus, if it came back.
    pub back_ms: Option<f64>,
    /// How far the robot truly moved between the kill and the successor's arrival (m).
    pub moved_m: Option<f64>,
    /// The service was not there to kill (the mission had ended).
    pub missed: bool,
}

/// How a killed run's recording compares with the reference.
#[derive(Debug, Clone, Default)]
pub struct Verdict {
    pub identical: bool,
    /// Messages of the reference the run lacks, and messages it has that the reference lacks.
    pub missing: usize,
    pub extra: usize,
    /// Simulated seconds between the first and the last message missing.
    pub missing_span_s: f64,
    /// Simulated time of the first message that differs.
    pub first_difference_s: Option<f64>,
    /// How far the robot's true end pose lies from the reference run's (m).
    pub end_apart_m: Option<f64>,
    pub missing_topics: BTreeSet<String>,
    /// The recording could not be read.
    pub unreadable: Option<String>,
}

/// One launch of the mission.
#[derive(Debug)]
pub struct Run {
    pub dir: PathBuf,
    pub exit_code: Option<i32>,
    /// Wall time from every service up to the launch's end.
    pub mission_wall: Duration,
    pub kills: Vec<Kill>,
    pub shm_left: usize,
    pub verdict: Verdict,
}

impl Run {
    pub fn new(
        dir: &Path,
        exit_code: Option<i32>,
        mission_wall: Duration,
        kills: Vec<Kill>,
        shm_left: usize,
    ) -> Self {
        Self { dir: dir.to_owned(), exit_code, mission_wall, kills, shm_left, verdict: Verdict::default() }
    }

    /// Compares this run's recording with the reference's.
    pub fn judge(&mut self, reference: &Path) {
        let all = |_: &str| true;
        let (a, b) = match (read_records(reference, &all), read_records(&self.dir.join("run.mcap"), &all)) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(e), _) | (_, Err(e)) => {
                self.verdict.unreadable = Some(e.to_string());
                return;
            }
        };
        self.verdict = verdict(&a, &b);
        self.verdict.end_apart_m =
            end_pose(&a).zip(end_pose(&b)).map(|(p, q)| (p.x_m - q.x_m).hypot(p.y_m - q.y_m));
    }

    /// One line for the log.
    pub fn line(&self) -> String {
        let kills: Vec<String> = self
            .kills
            .iter()
            .map(|k| match (k.missed, k.back_ms) {
                (true, _) => format!("{} (gone already)", k.service),
                (false, Some(ms)) => format!("{} at t = {:.2} s back in {ms:.0} ms", k.service, k.at_s),
                (false, None) => format!("{} at t = {:.2} s NEVER BACK", k.service, k.at_s),
            })
            .collect();
        let v = &self.verdict;
        let rec = match (&v.unreadable, v.identical) {
            (Some(e), _) => format!("recording unreadable: {e}"),
            (None, true) => "recording identical".into(),
            (None, false) => format!(
                "{} missing, {} extra from {:.2} s on {:?}",
                v.missing,
                v.extra,
                v.first_difference_s.unwrap_or(0.0),
                v.missing_topics
            ),
        };
        let rec = format!("{rec}; ends {:.3} m from the reference's end", v.end_apart_m.unwrap_or(f64::NAN));
        format!(
            "{}: exit {:?}; {}; {rec}; {} shm files left",
            self.dir.display(),
            self.exit_code,
            kills.join(", "),
            self.shm_left
        )
    }
}

/// The stamp of a recording's last true pose: how long the mission ran in simulated time.
pub fn last_truth_ns(recording: &Path) -> anyhow::Result<u64> {
    let truth = |t: &str| t == harvey_msgs::topics::SIM_TRUTH.name;
    let records = read_records(recording, &truth)?;
    records.last().map(|r| r.log_time).ok_or_else(|| anyhow::anyhow!("{}: no sim/truth", recording.display()))
}

/// The last true pose of a recording.
fn end_pose(records: &[Record]) -> Option<harvey_msgs::Pose2> {
    let last = records.iter().rev().find(|r| r.topic == harvey_msgs::topics::SIM_TRUTH.name)?;
    harvey_cdr::decode::<harvey_msgs::TruePose>(&last.data).ok().map(|t| t.world_from_robot)
}

fn verdict(a: &[Record], b: &[Record]) -> Verdict {
    if a == b {
        return Verdict { identical: true, ..Verdict::default() };
    }
    let key = |r: &Record| (r.topic.clone(), r.log_time, r.data.clone());
    let mut counts: HashMap<(String, u64, Vec<u8>), i64> = HashMap::new();
    for r in a {
        *counts.entry(key(r)).or_default() += 1;
    }
    for r in b {
        *counts.entry(key(r)).or_default() -= 1;
    }
    let mut v = Verdict::default();
    let (mut first, mut last) = (u64::MAX, 0);
    for ((topic, t, _), n) in &counts {
        if *n > 0 {
            v.missing += *n as usize;
            v.missing_topics.insert(topic.clone());
            (first, last) = (first.min(*t), last.max(*t));
        } else if *n < 0 {
            v.extra += (-n) as usize;
        }
    }
    v.missing_span_s = if v.missing > 0 { (last - first) as f64 / 1e9 } else { 0.0 };
    let at = a.iter().zip(b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len()));
    v.first_difference_s = a.get(at).or(b.get(at)).map(|r| r.log_time as f64 / 1e9);
    v
}

fn percentile(sorted: &[f64], p: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted.get(i).copied()
}

/// The figures as a Markdown table, per service and in all.
pub fn table(runs: &[Run], reference: &Run, cpu: &str) -> String {
    let mut services: Vec<String> =
        runs.iter().flat_map(|r| r.kills.iter().map(|k| k.service.clone())).collect();
    services.sort();
    services.dedup();
    let mut out = format!(
        "Chaos over {} runs ({} kills) on {cpu}; the reference run took {:.1} s of wall time.\n\n\
         | killed | kills | missions succeeded | end apart from the reference's, max (m) | back on the bus p50 / p99 (ms) | robot moved while it was gone, max (m) | recordings identical | messages missing / extra | shm files left |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        runs.len(),
        runs.iter().map(|r| r.kills.iter().filter(|k| !k.missed).count()).sum::<usize>(),
        reference.mission_wall.as_secs_f64()
    );
    let mut row = |name: &str, sel: &dyn Fn(&Run) -> bool, kill_sel: &dyn Fn(&Kill) -> bool| {
        let rs: Vec<&Run> = runs.iter().filter(|r| sel(r)).collect();
        let kills: Vec<&Kill> =
            rs.iter().flat_map(|r| r.kills.iter()).filter(|k| kill_sel(k) && !k.missed).collect();
        let mut back: Vec<f64> = kills.iter().filter_map(|k| k.back_ms).collect();
        back.sort_by(f64::total_cmp);
        let never = kills.len() - back.len();
        let lat = match (percentile(&back, 0.5), percentile(&back, 0.99)) {
            (Some(a), Some(b)) => format!(
                "{a:.0} / {b:.0}{}",
                if never > 0 { format!(" ({never} never)") } else { String::new() }
            ),
            _ => "-".into(),
        };
        let goal = rs.iter().filter(|r| r.exit_code == Some(0)).count();
        let same = rs.iter().filter(|r| r.verdict.identical).count();
        let missing: usize = rs.iter().map(|r| r.verdict.missing).sum();
        let extra: usize = rs.iter().map(|r| r.verdict.extra).sum();
        let apart = rs.iter().filter_map(|r| r.verdict.end_apart_m).fold(0.0, f64::max);
        let shm: usize = rs.iter().map(|r| r.shm_left).sum();
        let moved = kills
            .iter()
            .filter_map(|k| k.moved_m)
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
        let moved = moved.map_or("-".to_owned(), |m| format!("{m:.3}"));
        out += &format!(
            "| {name} | {} | {goal}/{} | {apart:.3} | {lat} | {moved} | {same}/{} | {missing} / {extra} | {shm} |\n",
            kills.len(),
            rs.len(),
            rs.len()
        );
    };
    for s in &services {
        row(s, &|r: &Run| r.kills.iter().any(|k| &k.service == s), &|k: &Kill| &k.service == s);
    }
    row("all", &|_| true, &|_| true);
    out
}

/// One line per kill, for plotting.
pub fn csv(runs: &[Run]) -> String {
    let mut out = String::from(
        "run,service,at_s,back_ms,exit_code,identical,missing,missing_span_s,extra,first_difference_s,end_apart_m,shm_left,missed,moved_m\n",
    );
    for r in runs {
        for k in &r.kills {
            out += &format!(
                "{},{},{:.3},{},{},{},{},{:.3},{},{},{},{},{},{}\n",
                r.dir.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned()),
                k.service,
                k.at_s,
                k.back_ms.map_or(String::new(), |b| format!("{b:.1}")),
                r.exit_code.map_or(String::new(), |c| c.to_string()),
                r.verdict.identical,
                r.verdict.missing,
                r.verdict.missing_span_s,
                r.verdict.extra,
                r.verdict.first_difference_s.map_or(String::new(), |t| format!("{t:.3}")),
                r.verdict.end_apart_m.map_or(String::new(), |m| format!("{m:.4}")),
                r.shm_left,
                k.missed,
                k.moved_m.map_or(String::new(), |m| format!("{m:.4}"))
            );
        }
    }
    out
}
