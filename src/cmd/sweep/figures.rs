//! A sweep's rows and statistics: which figure a mission is judged by (offset from the line when
//! it servoes, poles visited in a pole hunt, else the final error), one row per run, and per
//! condition the success rate, median, p90 and worst of the figure.

use std::path::PathBuf;

use crate::summary::Figures;

const INCH_M: f64 = 0.0254;

/// The number a mission is judged by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Figure {
    /// 000 §5.5: the largest offset of the true path from the line, inches.
    LineOffset,
    /// The true final position's distance from the goal, inches.
    FinalError,
    /// Poles visited (004 §5): more is better.
    PolesVisited,
    /// 000 §5.6 Table 1: the worst pose fix's distance from the truth, inches.
    FixError,
}

impl Figure {
    /// The figure of a launch file (`launch`) whose world (`world`) is given.
    pub fn for_mission(launch: &toml::Table, world: &toml::Table) -> Figure {
        let mission = launch.get("mission");
        let servoed = mission.and_then(|m| m.get("servo")).is_some();
        // A mission of pose fixes alone (refine steps, nothing driven): judged by its fixes.
        let steps = mission.and_then(|m| m.get("step")).and_then(|s| s.as_array());
        let fixes_only = mission.and_then(|m| m.get("refine")).is_some()
            && mission.and_then(|m| m.get("ptrans")).is_none()
            && steps.is_some_and(|s| !s.is_empty() && s.iter().all(|st| st.get("move_m").is_none()));
        if world.contains_key("poles") {
            Figure::PolesVisited
        } else if fixes_only {
            Figure::FixError
        } else if servoed {
            Figure::LineOffset
        } else {
            Figure::FinalError
        }
    }

    /// The label for tables and the plot's axis, with its unit.
    pub fn label(self) -> &'static str {
        match self {
            Figure::LineOffset => "offset from the line (in)",
            Figure::FinalError => "final error (in)",
            Figure::PolesVisited => "poles visited",
            Figure::FixError => "worst pose fix error (in)",
        }
    }

    pub fn lower_is_better(self) -> bool {
        self != Figure::PolesVisited
    }

    /// The figure of one run's figures.
    pub fn of(self, f: &Figures) -> Option<f64> {
        match self {
            Figure::LineOffset => f.line_offset_m.map(|m| m / INCH_M),
            Figure::FinalError => f.final_error_m.map(|m| m / INCH_M),
            Figure::PolesVisited => f.poles.map(|(n, _)| n as f64),
            Figure::FixError => f.fix_error_m.map(|m| m / INCH_M),
        }
    }
}

/// One finished run.
#[derive(Debug, Clone)]
pub struct Row {
    pub condition: String,
    pub seed: u64,
    /// `harvey run`'s exit code; `None` when it was killed by a signal.
    pub exit_code: Option<i32>,
    /// Read back from its recording; `None` without one.
    pub figures: Option<Figures>,
    pub figure: Option<f64>,
    /// The recording, when kept (always for a failed run).
    pub recording: Option<PathBuf>,
    /// `harvey run`'s output.
    pub log: PathBuf,
    pub wall_s: f64,
}

impl Row {
    /// A run succeeds when `harvey run` says the goal was reached (exit code 0).
    pub fn succeeded(&self) -> bool {
        self.exit_code == Some(0)
    }

    /// How the run ended, in a word.
    pub fn outcome(&self) -> &'static str {
        use harvey_msgs::MissionState::{Failed, Running, Succeeded};
        match (self.exit_code, self.figures.as_ref().and_then(|f| f.state)) {
            (Some(0), _) => "reached",
            (_, Some(Failed)) => "FAILED",
            (_, Some(Running)) => "stopped",
            (_, Some(Succeeded)) => "error",
            (_, None) => "no-status",
        }
    }

    /// The acceptor trace, `q0 q1 …` (empty without a sequenced behaviour).
    pub fn trace(&self) -> String {
        self.figures
            .as_ref()
            .map_or(String::new(), |f| f.trace.iter().map(|q| format!("q{q}")).collect::<Vec<_>>().join(" "))
    }
}

/// One condition's statistics of its figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Stats {
    pub runs: usize,
    pub successes: usize,
    /// Over the runs that have the figure, failed ones included.
    pub median: Option<f64>,
    /// The figure 90 % of the runs are at least as good as (nearest rank).
    pub p90: Option<f64>,
    pub worst: Option<f64>,
}

impl Stats {
    pub fn of<'a>(rows: impl IntoIterator<Item = &'a Row>, figure: Figure) -> Stats {
        let rows: Vec<&Row> = rows.into_iter().collect();
        let mut v: Vec<f64> = rows.iter().filter_map(|r| r.figure).collect();
        // Best first.
        v.sort_by(|a, b| if figure.lower_is_better() { a.total_cmp(b) } else { b.total_cmp(a) });
        let n = v.len();
        let median = match n {
            0 => None,
            _ if n % 2 == 1 => Some(v[n / 2]),
            _ => Some((v[n / 2 - 1] + v[n / 2]) / 2.0),
        };
        let p90 = (n > 0).then(|| v[(n * 9).div_ceil(10) - 1]);
        Stats {
            runs: rows.len(),
            successes: rows.iter().filter(|r| r.succeeded()).count(),
            median,
            p90,
            worst: v.last().copied(),
        }
    }

    pub fn success_rate(&self) -> f64 {
        if self.runs == 0 { 0.0 } else { self.successes as f64 / self.runs as f64 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(code: i32, figure: Option<f64>) -> Row {
        Row {
            condition: "c".into(),
            seed: 1,
            exit_code: Some(code),
            figures: None,
            figure,
            recording: None,
            log: PathBuf::new(),
            wall_s: 0.0,
        }
    }

    #[test]
    fn statistics_of_an_error_figure() {
        let rows: Vec<Row> = [3.0, 1.0, 2.0, 10.0, 4.0].iter().map(|&v| row(0, Some(v))).collect();
        let s = Stats::of(&rows, Figure::FinalError);
        assert_eq!(
            (s.runs, s.successes, s.median, s.p90, s.worst),
            (5, 5, Some(3.0), Some(10.0), Some(10.0))
        );
        let mut rows: Vec<Row> = (1..=10).map(|v| row(0, Some(f64::from(v)))).collect();
        rows[9].exit_code = Some(1);
        rows.push(row(2, None));
        let s = Stats::of(&rows, Figure::LineOffset);
        assert_eq!((s.runs, s.successes), (11, 9));
        assert_eq!((s.median, s.p90, s.worst), (Some(5.5), Some(9.0), Some(10.0)));
        assert!((s.success_rate() - 9.0 / 11.0).abs() < 1e-12);
    }

    #[test]
    fn more_poles_are_better() {
        let rows: Vec<Row> = [10.0, 9.0, 7.0, 10.0].iter().map(|&v| row(0, Some(v))).collect();
        let s = Stats::of(&rows, Figure::PolesVisited);
        assert_eq!((s.median, s.p90, s.worst), (Some(9.5), Some(7.0), Some(7.0)));
        let none = Stats::of(&[], Figure::PolesVisited);
        assert_eq!((none.runs, none.median, none.success_rate()), (0, None, 0.0));
    }

    #[test]
    fn the_figure_follows_the_mission() {
        let t = |s: &str| -> toml::Table { toml::from_str(s).expect("toml") };
        let plain = t("[mission]\ntimeout_s = 1.0\n");
        let servo = t("[mission.servo]\naim_m = 0.6\n");
        assert_eq!(Figure::for_mission(&plain, &t("")), Figure::FinalError);
        assert_eq!(Figure::for_mission(&servo, &t("")), Figure::LineOffset);
        assert_eq!(Figure::for_mission(&plain, &t("[poles]\ncount = 10\n")), Figure::PolesVisited);
        let f = Figures { final_error_m: Some(0.0254), line_offset_m: Some(0.127), ..Figures::default() };
        assert_eq!(Figure::FinalError.of(&f), Some(1.0));
        assert!((Figure::LineOffset.of(&f).expect("offset") - 5.0).abs() < 1e-12);
    }
}
