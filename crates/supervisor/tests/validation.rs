//! Issue 20's defects in launch files, each refused when the file is loaded, naming file, line
//! and key: an infinite restart window (it panicked the supervisor when a service died), no
//! `end_with` (the mission finished and the launch never returned), no grace period (the recorder
//! was SIGKILLed and a successful mission exited 2); and every shipped mission still loads.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use std::path::Path;

use harvey_supervisor::LaunchFile;

const OK: &str = "[launch]\nname = \"t\"\nend_with = \"b\"\ngrace_period_ms = 3000\n\n[[service]]\nname = \"a\"\nrestart_window_s = 60\n\n[[service]]\nname = \"b\"\nrestart = \"never\"\n";

fn refused(text: &str) -> String {
    LaunchFile::parse(text, Path::new("m.toml")).expect_err("must be refused").to_string()
}

#[test]
fn an_infinite_or_impossible_restart_window_is_refused() {
    LaunchFile::parse(OK, Path::new("m.toml")).expect("the good file parses");
    let cases = [
        ("inf", "inf is not a finite number in"),
        ("nan", "NaN is not a finite"),
        ("0", "0 is outside"),
        ("-1", "-1 is outside"),
        ("1e300", "1e300 is outside"),
    ];
    for (value, shown) in cases {
        let e = refused(&OK.replace("restart_window_s = 60", &format!("restart_window_s = {value}")));
        assert!(e.starts_with(&format!("m.toml:8: key `service[0].restart_window_s`: {shown}")), "{e}");
    }
}

#[test]
fn a_launch_without_end_with_is_refused_naming_the_file() {
    let e = refused(&OK.replace("end_with = \"b\"\n", ""));
    assert!(e.starts_with("m.toml: key `launch.end_with`: missing"), "{e}");
}

#[test]
fn a_grace_period_below_the_floor_is_refused() {
    for value in ["0", "199"] {
        let e = refused(&OK.replace("grace_period_ms = 3000", &format!("grace_period_ms = {value}")));
        let want = format!("m.toml:4: key `launch.grace_period_ms`: {value} is outside [200, 600000] ms");
        assert!(e.starts_with(&want), "{e}");
    }
    assert!(LaunchFile::parse(&OK.replace("3000", "200"), Path::new("m.toml")).is_ok(), "the floor itself");
}

#[test]
fn waits_backoffs_and_restart_counts_are_bounded() {
    let cases = [
        ("[launch]", "[launch]\nready_timeout_ms = 0", "launch.ready_timeout_ms", 2),
        ("[launch]", "[launch]\nready_timeout_ms = 9223372036854775807", "launch.ready_timeout_ms", 2),
        ("grace_period_ms = 3000", "grace_period_ms = 18446744073709551", "launch.grace_period_ms", 4),
        (
            "restart_window_s = 60",
            "restart_window_s = 60\nmax_restarts = 4000000000",
            "service[0].max_restarts",
            9,
        ),
        ("restart_window_s = 60", "restart_window_s = 60\nbackoff_ms = 0", "service[0].backoff_ms", 9),
        ("restart_window_s = 60", "restart_window_s = 60\nbackoff_ms = 5000", "service[0].backoff_max_ms", 6),
        (
            "restart_window_s = 60",
            "restart_window_s = 60\nbackoff_max_ms = 9999999999",
            "service[0].backoff_max_ms",
            9,
        ),
    ];
    for (from, to, key, line) in cases {
        let e = refused(&OK.replacen(from, to, 1));
        assert!(e.starts_with(&format!("m.toml:{line}: key `{key}`")), "{to}: {e}");
    }
}

#[test]
fn every_shipped_mission_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../missions");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("missions/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            LaunchFile::load(&path).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert!(n >= 10, "{n} missions");
}
