//! Reading a recording back: per-topic counts, rates and gaps (`harvey info`), and the mission
//! summary `harvey run` prints, all from `run.mcap` alone.

use std::collections::BTreeMap;
use std::path::Path;

use harvey_msgs::{CheckOutcome, MissionState, MissionStatus, PlanSketch, PoseFix, TruePose, UncertaintyMap};
use harvey_recording::Recording;

/// One line of the summary: a labelled pose, its heading in (-180, 180] degrees.
fn pose_line(label: &str, p: &harvey_msgs::Pose2) -> String {
    let deg = p.heading_rad.to_degrees();
    let deg = 180.0 - (180.0 - deg).rem_euclid(360.0);
    format!("  {label:<11} x {:7.3} m  y {:7.3} m  heading {deg:7.2} deg\n", p.x_m, p.y_m)
}

/// What one topic of a recording holds.
#[derive(Debug, Default, Clone)]
pub struct TopicStats {
    pub schema: String,
    pub messages: u64,
    pub first_ns: u64,
    pub last_ns: u64,
    pub seq_gaps: Option<u64>,
}

/// A recording read back.
#[derive(Debug, Default)]
pub struct RunStats {
    pub topics: BTreeMap<String, TopicStats>,
    pub last_status: Option<MissionStatus>,
    pub last_truth: Option<TruePose>,
    pub last_map: Option<UncertaintyMap>,
    pub last_plan: Option<PlanSketch>,
    /// Milestone checks by outcome (reached, retried, replanned), and pose fixes.
    pub checks: [u32; 3],
    pub fixes: u32,
    /// The states a sequenced behaviour's acceptor went through, and what it achieved (poles
    /// parked by; 1 once docked).
    pub fsa_trace: Vec<u32>,
    pub achieved: u32,
    /// In a world with `[poles]`: when the true path first came by each pole (code order), and
    /// how close counts.
    pub pole_visits: Option<(Vec<Option<f64>>, f64)>,
    /// The largest distance of the true path from the line through its first pose along that
    /// pose's heading (000 §5.5's offset from the line); `None` without `sim/truth`.
    pub line_offset_m: Option<f64>,
    /// Each pose fix's distance from the true pose when its frames were taken (metres).
    pub fix_errors_m: Vec<f64>,
    /// The UMS's maps that do not hold the true pose at their stamp, and the maps checked
    /// (those with a true pose at or before them); `None` without both topics.
    pub ums_truth: Option<(usize, usize)>,
}

/// A run's figures as data (`harvey sweep` tabulates them): the numbers the mission summary
/// prints, computed the same way.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Figures {
    /// The last executive status's state; `None` when none was recorded.
    pub state: Option<MissionState>,
    /// Simulated time of the last status, s.
    pub end_s: Option<f64>,
    /// The summary's "final error … from the goal" (not for a pole hunt).
    pub final_error_m: Option<f64>,
    pub line_offset_m: Option<f64>,
    /// The worst pose fix's distance from the truth (metres); `None` without fixes.
    pub fix_error_m: Option<f64>,
    /// Poles visited and poles in the field.
    pub poles: Option<(usize, usize)>,
    /// The acceptor's states (empty without a sequenced behaviour) and what it achieved.
    pub trace: Vec<u32>,
    pub achieved: u32,
    /// The UMS's maps without the true pose, of the maps checked.
    pub ums_truth: Option<(usize, usize)>,
}

/// How far outside a map the truth may lie and still count as held (metres): rounding.
const HOLDS_TOL_M: f64 = 1e-6;

/// The maps that do not hold the true pose of their stamp, and the maps checked (those with a
/// true pose of the same stamp: both are stamped on the simulator's ticks); `None` without such.
fn ums_truth(maps: &[UncertaintyMap], truth: &mut [(u64, harvey_msgs::Pose2)]) -> Option<(usize, usize)> {
    truth.sort_by_key(|(t, _)| *t);
    let at = |stamp: u64| truth.binary_search_by_key(&stamp, |(t, _)| *t).ok().map(|k| truth[k].1);
    let checked: Vec<bool> =
        maps.iter().filter_map(|m| at(m.header.stamp_ns).map(|p| m.holds(&p, HOLDS_TOL_M))).collect();
    (!checked.is_empty()).then(|| (checked.iter().filter(|h| !**h).count(), checked.len()))
}

impl RunStats {
    pub fn read(path: &Path) -> anyhow::Result<Self> {
        let recording = Recording::open(path)?;
        let mut run = RunStats::default();
        let mut true_path: Vec<(f64, [f64; 2])> = Vec::new();
        let mut true_poses: Vec<(u64, harvey_msgs::Pose2)> = Vec::new();
        let mut maps: Vec<UncertaintyMap> = Vec::new();
        // The line of `line_offset_m`: the first true pose's x, y, cos and sin of its heading.
        let mut line: Option<[f64; 4]> = None;
        let mut fixes: Vec<PoseFix> = Vec::new();
        for m in recording.messages()? {
            let m = m?;
            let topic = m.topic().to_owned();
            let t = run.topics.entry(topic.clone()).or_default();
            if t.messages == 0 {
                t.first_ns = m.log_time();
                t.schema = m.schema().to_owned();
            }
            t.messages += 1;
            t.last_ns = m.log_time();
            match topic.as_str() {
                "executive/status" => run.last_status = Some(m.decode()?),
                "sim/truth" => {
                    let t: TruePose = m.decode()?;
                    let p = t.world_from_robot;
                    true_path.push((t.header.stamp_ns as f64 / 1e9, [p.x_m, p.y_m]));
                    true_poses.push((t.header.stamp_ns, p));
                    let [x0, y0, c, s] = *line.get_or_insert_with(|| {
                        let (s, c) = p.heading_rad.sin_cos();
                        [p.x_m, p.y_m, c, s]
                    });
                    let off = (-(p.x_m - x0) * s + (p.y_m - y0) * c).abs();
                    run.line_offset_m = Some(run.line_offset_m.map_or(off, |m: f64| m.max(off)));
                    run.last_truth = Some(t);
                }
                "ums/map" => {
                    let map: UncertaintyMap = m.decode()?;
                    maps.push(map);
                    run.last_map = Some(map);
                }
                "executive/pose" => {
                    run.fixes += 1;
                    fixes.push(m.decode::<PoseFix>()?);
                }
                "executive/behaviour" => {
                    let b: harvey_msgs::BehaviourState = m.decode()?;
                    if run.fsa_trace.last() != Some(&b.fsa_state) {
                        run.fsa_trace.push(b.fsa_state);
                    }
                    run.achieved = b.achieved;
                }
                "executive/plan" => {
                    let p: PlanSketch = m.decode()?;
                    let checks_before = run.last_plan.map_or(0, |q| q.checks);
                    if p.checks > checks_before {
                        let k = match p.last_outcome {
                            o if o == CheckOutcome::Reached as u32 => 0,
                            o if o == CheckOutcome::Retried as u32 => 1,
                            _ => 2,
                        };
                        run.checks[k] += 1;
                    }
                    run.last_plan = Some(p);
                }
                _ => {}
            }
        }
        for f in &fixes {
            let at_s = f.header.stamp_ns as f64 / 1e9;
            let truth = true_path.iter().rev().find(|(t, _)| *t <= at_s + 1e-9);
            if let Some((_, [x, y])) = truth {
                run.fix_errors_m.push((f.refined.x_m - x).hypot(f.refined.y_m - y));
            }
        }
        run.ums_truth = ums_truth(&maps, &mut true_poses);
        match recording.world() {
            Ok(Some((w, poles))) => {
                if let Some(f) = w.poles.as_ref() {
                    run.pole_visits = Some((f.first_visits(&poles, &true_path), f.visit_m));
                }
            }
            Ok(None) => {}
            Err(e) => tracing::warn!("{e}; poles not counted"),
        }
        for (topic, gaps) in recording.seq_gaps()? {
            if let Some(t) = run.topics.get_mut(&topic) {
                t.seq_gaps = gaps;
            }
        }
        Ok(run)
    }

    pub fn message_count(&self) -> u64 {
        self.topics.values().map(|t| t.messages).sum()
    }

    /// The table `harvey info` prints.
    pub fn info_table(&self) -> String {
        let mut out =
            format!("{:<22} {:>8} {:>9} {:>8}  {}\n", "topic", "messages", "rate_hz", "seq_gaps", "type");
        for (name, t) in &self.topics {
            let span_s = (t.last_ns.saturating_sub(t.first_ns)) as f64 / 1e9;
            let rate = if span_s > 0.0 { (t.messages - 1) as f64 / span_s } else { 0.0 };
            let gaps = t.seq_gaps.map_or("-".into(), |g| g.to_string());
            out += &format!("/{name:<21} {:>8} {rate:>9.2} {gaps:>8}  {}\n", t.messages, t.schema);
        }
        let first = self.topics.values().map(|t| t.first_ns).min().unwrap_or(0);
        let last = self.topics.values().map(|t| t.last_ns).max().unwrap_or(0);
        out += &format!(
            "{} messages over {:.2} s of simulated time\n",
            self.message_count(),
            (last - first) as f64 / 1e9
        );
        out
    }

    /// The figures of [`Self::mission_summary`] as data.
    pub fn figures(&self) -> Figures {
        let mut f = Figures {
            state: self.last_status.as_ref().and_then(MissionStatus::state),
            end_s: self.last_status.as_ref().map(|s| s.header.stamp_ns as f64 / 1e9),
            line_offset_m: self.line_offset_m,
            fix_error_m: self.fix_errors_m.iter().copied().reduce(f64::max),
            trace: self.fsa_trace.clone(),
            achieved: self.achieved,
            ums_truth: self.ums_truth,
            ..Figures::default()
        };
        if let (Some(s), Some(t), None) = (&self.last_status, &self.last_truth, &self.pole_visits) {
            let (g, p) = (s.goal, t.world_from_robot);
            f.final_error_m = Some((p.x_m - g.x_m).hypot(p.y_m - g.y_m));
        }
        if let Some((visits, _)) = &self.pole_visits {
            f.poles = Some((visits.iter().flatten().count(), visits.len()));
        }
        f
    }

    /// The mission summary `harvey run` prints.
    pub fn mission_summary(&self) -> String {
        let mut out = String::new();
        let Some(s) = &self.last_status else {
            return "mission: no executive status was recorded\n".into();
        };
        let state = match s.state() {
            Some(MissionState::Succeeded) => "goal reached",
            Some(MissionState::Failed) => "FAILED",
            _ => "still running when stopped",
        };
        // A behaviour runs no script: no steps to count.
        let steps =
            if s.step_count > 0 { format!(" ({}/{} steps)", s.step, s.step_count) } else { String::new() };
        out += &format!("mission: {state}{steps} at t = {:.2} s\n", s.header.stamp_ns as f64 / 1e9);
        // A pole hunt's goal is only the pole it went for last: its poles are its figure.
        let g = s.goal;
        if self.pole_visits.is_none() {
            out += &pose_line("goal", &g);
        }
        out += &pose_line("estimated", &s.estimated);
        if let Some(t) = &self.last_truth {
            let p = t.world_from_robot;
            out += &pose_line("true", &p);
            if self.pole_visits.is_none() {
                let err = (p.x_m - g.x_m).hypot(p.y_m - g.y_m);
                out += &format!("  final error {:.3} m ({:.2} in) from the goal\n", err, err / 0.0254);
            }
        }
        if let Some((visits, within_m)) = &self.pole_visits {
            let times: Vec<f64> = visits.iter().flatten().copied().collect();
            let last = times.iter().copied().reduce(f64::max);
            out += &format!(
                "  poles visited {} of {} (true path within {within_m:.2} m of a pole){}\n",
                times.len(),
                visits.len(),
                last.map_or(String::new(), |t| format!(", the last first reached at t = {t:.2} s"))
            );
        }
        if let Some(m) = &self.last_map {
            let wedge = (m.heading_ccw_rad + m.heading_cw_rad).to_degrees();
            out += &format!(
                "  uncertainty area {:.5} m^2 ({} vertices), heading wedge {:.2} deg{}\n",
                m.area_m2,
                m.vertex_count,
                wedge,
                if m.lost == 1 { ", LOST" } else { "" }
            );
        }
        if let Some((without, of)) = self.ums_truth {
            out += &format!("  the true pose inside the uncertainty map: {} of {of} maps\n", of - without);
        }
        if self.last_plan.is_some() {
            let [reached, retried, replanned] = self.checks;
            out += &format!(
                "  plan-and-monitor: {} milestone checks ({reached} reached, {retried} retried, {replanned} replanned), {} pose fixes\n",
                reached + retried + replanned,
                self.fixes
            );
        }
        if let Some(worst) = self.fix_errors_m.iter().copied().reduce(f64::max) {
            out += &format!(
                "  pose fixes: {}, at most {:.3} m ({:.2} in) from the truth\n",
                self.fix_errors_m.len(),
                worst,
                worst / 0.0254
            );
        }
        if !self.fsa_trace.is_empty() {
            let trace: Vec<String> = self.fsa_trace.iter().take(40).map(|q| format!("q{q}")).collect();
            let more = if self.fsa_trace.len() > 40 { " ..." } else { "" };
            out += &format!("  acceptor trace: {}{more}; achieved {}\n", trace.join(" "), self.achieved);
        }
        out += &format!(
            "  data seen by the executive: {} sonar rings, {} detections, {} maps\n",
            s.sonar_rings_seen, s.detections_seen, s.maps_seen
        );
        out
    }
}

#[cfg(test)]
#[allow(dead_code, reason = "the harness's sample, damage and campaign; its tools are the crate's")]
#[path = "../crates/recording/tests/mutation/mod.rs"]
mod mutation;

#[cfg(test)]
mod tests {
    use super::*;
    use mutation::tools::{Case, Output, fingerprint};

    /// What `harvey info` prints for a recording, or `None` for the error it reports.
    fn info(case: &Case<'_>) -> Result<Output, String> {
        let stats = RunStats::read(case.mutated).ok();
        Ok(vec![stats.map(|s| fingerprint(&(s.info_table(), s.mission_summary(), s.pole_visits.is_some())))])
    }

    #[test]
    fn info_reports_every_damage_it_reads_and_never_panics() {
        let c = mutation::campaign("info", info, 400, 7);
        println!("{}", mutation::table(&[("info", &c)]));
        mutation::assert_kept("info", &c);
    }
}
