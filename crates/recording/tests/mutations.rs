//! The mutation harness in CI: 1,000 seeded mutations of a small recording (cuts, bit flips,
//! length fields rewritten, CRCs edited) through each tool entry point of the crate, none of
//! which may panic, abort, hang or give another answer than for the intact file without
//! reporting the damage. `benches/mutations.rs` runs ten times as many and prints the table.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod mutation;

use mutation::tools::TOOLS;

const CASES: usize = 1_000;

fn run(tool: &str) {
    let &(name, entry) = TOOLS.iter().find(|(name, _)| *name == tool).expect("a tool");
    let c = mutation::campaign(name, entry, CASES, 14);
    println!("{}", mutation::table(&[(name, &c)]));
    mutation::assert_kept(name, &c);
}

#[test]
fn messages_report_every_damage_they_read() {
    run("messages");
}

#[test]
fn compare_reports_every_damage_it_reads() {
    run("compare");
}

#[test]
fn recover_salvages_only_what_its_crcs_vouch_for() {
    run("recover");
}

#[test]
fn export_reports_every_damage_it_reads() {
    run("export");
}

#[test]
fn the_tick_splitter_reports_every_damage_it_reads() {
    run("ticks");
}

#[test]
fn attachments_and_the_world_report_every_damage_they_read() {
    run("attachments");
}
