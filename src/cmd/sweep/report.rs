//! Writing a sweep's results: `sweep.csv` (one row per run, numbers at full precision) and
//! `sweep.md` (per condition success rate, median, p90 and worst; per run outcome and figure, a
//! failed run's recording named).

use std::fmt::Write as _;
use std::path::Path;

use super::figures::{Figure, Row, Stats};

/// What the report says about the sweep as a whole.
pub struct Header<'a> {
    pub mission: &'a Path,
    pub name: &'a str,
    pub seeds: &'a str,
    /// Condition names and files, in sweep order.
    pub conditions: &'a [(String, String)],
    pub figure: Figure,
    /// Runs planned (more than rows when interrupted).
    pub planned: usize,
}

const INCH_M: f64 = 0.0254;

/// A CSV field, quoted when it must be.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_owned() }
}

fn num(v: Option<f64>) -> String {
    v.map_or(String::new(), |v| v.to_string())
}

pub fn csv(rows: &[Row], figure: Figure) -> String {
    let mut out = String::from(
        "condition,seed,outcome,exit_code,figure_name,figure,final_error_in,line_offset_in,poles_visited,poles_total,trace,achieved,end_s,wall_s,recording,log,ums_maps_without_truth,ums_maps\n",
    );
    for r in rows {
        let f = r.figures.as_ref();
        let cells = [
            field(&r.condition),
            r.seed.to_string(),
            r.outcome().to_owned(),
            r.exit_code.map_or(String::new(), |c| c.to_string()),
            field(figure.label()),
            num(r.figure),
            num(f.and_then(|f| f.final_error_m).map(|m| m / INCH_M)),
            num(f.and_then(|f| f.line_offset_m).map(|m| m / INCH_M)),
            f.and_then(|f| f.poles).map_or(String::new(), |p| p.0.to_string()),
            f.and_then(|f| f.poles).map_or(String::new(), |p| p.1.to_string()),
            field(&r.trace()),
            f.map_or(String::new(), |f| f.achieved.to_string()),
            num(f.and_then(|f| f.end_s)),
            format!("{:.1}", r.wall_s),
            field(&r.recording.as_ref().map_or(String::new(), |p| p.display().to_string())),
            field(&r.log.display().to_string()),
            f.and_then(|f| f.ums_truth).map_or(String::new(), |t| t.0.to_string()),
            f.and_then(|f| f.ums_truth).map_or(String::new(), |t| t.1.to_string()),
        ];
        out += &cells.join(",");
        out.push('\n');
    }
    out
}

fn cell(v: Option<f64>, figure: Figure) -> String {
    match (v, figure) {
        (None, _) => "-".into(),
        (Some(v), Figure::PolesVisited) => format!("{v:.1}"),
        (Some(v), _) => format!("{v:.2}"),
    }
}

/// A cell of a Markdown table: no `|` or line break inside.
fn md(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

pub fn markdown(h: &Header<'_>, rows: &[Row]) -> String {
    let fig = h.figure;
    let better = if fig.lower_is_better() { "lower is better" } else { "higher is better" };
    let mut out = format!("# harvey sweep: {}\n\n", md(h.name));
    let _ = writeln!(
        out,
        "Mission `{}`, seeds {}, {} of {} runs finished.",
        h.mission.display(),
        h.seeds,
        rows.len(),
        h.planned
    );
    let _ = writeln!(out, "Figure: {} ({better}).", fig.label());
    let conds: Vec<String> = h.conditions.iter().map(|(n, f)| format!("`{}` ({})", md(n), md(f))).collect();
    let _ = writeln!(out, "Conditions: {}.\n", conds.join(", "));
    out += "## Per condition\n\n";
    let _ = writeln!(out, "| condition | runs | successes | success rate | median | p90 | worst |");
    out += "|---|---:|---:|---:|---:|---:|---:|\n";
    for (name, _) in h.conditions {
        let s = Stats::of(rows.iter().filter(|r| &r.condition == name), fig);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.0} % | {} | {} | {} |",
            md(name),
            s.runs,
            s.successes,
            100.0 * s.success_rate(),
            cell(s.median, fig),
            cell(s.p90, fig),
            cell(s.worst, fig)
        );
    }
    out += "\nMedian, p90 (the value 90 % of the runs are at least as good as, nearest rank) and \
            worst are over the runs that have the figure, failed runs included.\n\n";
    out += "## Per run\n\n";
    let _ = writeln!(out, "| condition | seed | outcome | {} | acceptor trace | recording |", fig.label());
    out += "|---|---:|---|---:|---|---|\n";
    for r in rows {
        let trace = r.trace();
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} |",
            md(&r.condition),
            r.seed,
            r.outcome(),
            cell(r.figure, fig),
            if trace.is_empty() { "-".into() } else { md(&trace) },
            r.recording.as_ref().map_or("-".into(), |p| format!("`{}`", md(&p.display().to_string())))
        );
    }
    out
}

/// Writes `sweep.csv` and `sweep.md` into `out`.
pub fn write(out: &Path, h: &Header<'_>, rows: &[Row]) -> std::io::Result<()> {
    std::fs::write(out.join("sweep.csv"), csv(rows, h.figure))?;
    std::fs::write(out.join("sweep.md"), markdown(h, rows))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::summary::Figures;

    #[test]
    fn fields_are_quoted_when_they_must_be() {
        assert_eq!(field("a b"), "a b");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
    }

    #[test]
    fn the_tables_hold_every_row_and_condition() {
        let f = Figures {
            final_error_m: Some(0.0508),
            trace: vec![0, 1, 2],
            ums_truth: Some((3, 500)),
            ..Figures::default()
        };
        let row = |c: &str, seed, code| Row {
            condition: c.into(),
            seed,
            exit_code: Some(code),
            figures: Some(f.clone()),
            figure: Some(2.0),
            recording: (code != 0).then(|| "out/runs/x/run.mcap".into()),
            log: "out/runs/x/harvey-run.log".into(),
            wall_s: 1.0,
        };
        let rows = [row("nominal", 1, 0), row("dim", 1, 1)];
        let conditions = [("nominal".into(), "n.toml".into()), ("dim".into(), "d.toml".into())];
        let h = Header {
            mission: Path::new("m.toml"),
            name: "m",
            seeds: "1..1",
            conditions: &conditions,
            figure: Figure::FinalError,
            planned: 2,
        };
        let c = csv(&rows, h.figure);
        assert_eq!(c.lines().count(), 3);
        assert!(c.lines().nth(2).expect("row").starts_with("dim,1,no-status,1,final error (in),2,2,"), "{c}");
        assert!(c.lines().nth(2).expect("row").ends_with(",out/runs/x/harvey-run.log,3,500"), "{c}");
        let m = markdown(&h, &rows);
        assert!(m.contains("| nominal | 1 | 1 | 100 % | 2.00 | 2.00 | 2.00 |"), "{m}");
        assert!(m.contains("| dim | 1 | no-status | 2.00 | q0 q1 q2 | `out/runs/x/run.mcap` |"), "{m}");
    }
}
