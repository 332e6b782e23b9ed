//! Unit tests of the restart policy, on made-up instants.

use super::*;

fn rules(mode: Restart) -> RestartRules {
    RestartRules {
        mode,
        max_restarts: 5,
        window: Duration::from_secs(60),
        backoff_ms: 50,
        backoff_max_ms: 2000,
    }
}

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

/// The delay of a restart decision, or a panic naming what was decided instead.
fn delay(d: Decision) -> Duration {
    match d {
        Decision::Restart { delay, .. } => delay,
        other => panic!("expected a restart, got {other:?}"),
    }
}

#[test]
fn never_restarts_nothing() {
    let t0 = Instant::now();
    let mut p = RestartPolicy::new(rules(Restart::Never));
    assert_eq!(p.on_exit(t0, false), Decision::Stay);
    assert_eq!(p.on_exit(t0, true), Decision::Stay);
    assert_eq!(p.next_restart(), None);
}

#[test]
fn on_failure_restarts_failures_only() {
    let t0 = Instant::now();
    let mut p = RestartPolicy::new(rules(Restart::OnFailure));
    assert_eq!(p.on_exit(t0, true), Decision::Stay);
    assert_eq!(p.next_restart(), None);
    assert_eq!(p.on_exit(t0, false), Decision::Restart { at: t0 + ms(50), delay: ms(50), attempt: 1 });
    assert_eq!(p.next_restart(), Some(t0 + ms(50)));
}

#[test]
fn always_restarts_clean_exits_too() {
    let t0 = Instant::now();
    let mut p = RestartPolicy::new(rules(Restart::Always));
    assert_eq!(p.on_exit(t0, true), Decision::Restart { at: t0 + ms(50), delay: ms(50), attempt: 1 });
    assert_eq!(delay(p.on_exit(t0 + ms(100), false)), ms(100), "a success counts like a failure");
}

#[test]
fn the_backoff_doubles_up_to_the_cap() {
    let t0 = Instant::now();
    let mut p = RestartPolicy::new(RestartRules { max_restarts: 10, ..rules(Restart::OnFailure) });
    let delays: Vec<_> =
        (0..8).map(|i| delay(p.on_exit(t0 + Duration::from_secs(i), false)).as_millis()).collect();
    assert_eq!(delays, [50, 100, 200, 400, 800, 1600, 2000, 2000]);
}

#[test]
fn the_doubling_stops_after_sixteen() {
    let t0 = Instant::now();
    let rules =
        RestartRules { max_restarts: 100, backoff_ms: 1, backoff_max_ms: u64::MAX, ..rules(Restart::Always) };
    let mut p = RestartPolicy::new(rules);
    let delays: Vec<_> = (0..20).map(|i| delay(p.on_exit(t0 + ms(i), true)).as_millis()).collect();
    assert_eq!(delays[16], 1 << 16);
    assert!(delays[17..].iter().all(|&d| d == 1 << 16), "{delays:?}");
}

#[test]
fn more_restarts_than_allowed_within_the_window_give_up() {
    let t0 = Instant::now();
    let mut p = RestartPolicy::new(RestartRules { max_restarts: 2, ..rules(Restart::OnFailure) });
    assert_eq!(p.on_exit(t0, false), Decision::Restart { at: t0 + ms(50), delay: ms(50), attempt: 1 });
    assert_eq!(
        p.on_exit(t0 + ms(200), false),
        Decision::Restart { at: t0 + ms(300), delay: ms(100), attempt: 2 }
    );
    assert_eq!(p.on_exit(t0 + ms(500), false), Decision::GiveUp);
}

#[test]
fn failures_older_than_the_window_are_forgotten() {
    let t0 = Instant::now();
    let window = Duration::from_secs(10);
    let mut p = RestartPolicy::new(RestartRules { max_restarts: 2, window, ..rules(Restart::OnFailure) });
    for i in 0..10 {
        // Two failures a second apart, a window after the last: never more than allowed within a
        // window, and the backoff starts over.
        let at = t0 + (window + Duration::from_secs(1)) * i;
        assert_eq!(delay(p.on_exit(at, false)), ms(50), "round {i}");
        assert_eq!(delay(p.on_exit(at + Duration::from_secs(1), false)), ms(100), "round {i}");
    }
    // A failure exactly one window old no longer counts.
    let mut p = RestartPolicy::new(RestartRules { max_restarts: 1, window, ..rules(Restart::OnFailure) });
    assert_eq!(delay(p.on_exit(t0, false)), ms(50));
    assert_eq!(delay(p.on_exit(t0 + window, false)), ms(50));
    assert_eq!(p.on_exit(t0 + window + ms(1), false), Decision::GiveUp);
}

#[test]
fn a_restart_is_due_once_at_its_time() {
    let t0 = Instant::now();
    let mut p = RestartPolicy::new(rules(Restart::OnFailure));
    assert!(!p.take_due(t0), "nothing pending");
    p.on_exit(t0, false);
    assert!(!p.take_due(t0 + ms(49)));
    assert_eq!(p.next_restart(), Some(t0 + ms(50)));
    assert!(p.take_due(t0 + ms(50)));
    assert!(!p.take_due(t0 + ms(51)), "taken once");
    assert_eq!(p.next_restart(), None);
}

#[test]
fn a_failed_start_waits_the_cap_and_counts_towards_the_limit() {
    let t0 = Instant::now();
    let mut p = RestartPolicy::new(RestartRules { max_restarts: 2, ..rules(Restart::OnFailure) });
    p.on_exit(t0, false);
    assert!(p.take_due(t0 + ms(50)));
    assert_eq!(
        p.on_failed_start(t0 + ms(60)),
        Decision::Restart { at: t0 + ms(2060), delay: ms(2000), attempt: 2 }
    );
    assert!(p.take_due(t0 + ms(2060)));
    assert_eq!(p.on_failed_start(t0 + ms(2100)), Decision::GiveUp);
    assert_eq!(p.next_restart(), None, "no restart after giving up");
}

#[test]
fn a_failed_start_does_not_forget_old_failures() {
    let t0 = Instant::now();
    let window = Duration::from_secs(1);
    let mut p = RestartPolicy::new(RestartRules { max_restarts: 1, window, ..rules(Restart::OnFailure) });
    p.on_exit(t0, false);
    assert_eq!(p.on_failed_start(t0 + Duration::from_secs(5)), Decision::GiveUp);
}

#[test]
fn the_window_comes_from_the_launch_file_and_never_panics() {
    let text = "[launch]\nname = \"t\"\nend_with = \"a\"\n\n[[service]]\nname = \"a\"\nrestart_window_s = 1e300\nbackoff_ms = 7\n";
    let e = crate::LaunchFile::parse(text, std::path::Path::new("m.toml")).expect_err("a window of 1e300 s");
    assert!(
        e.to_string().starts_with("m.toml:7: key `service[0].restart_window_s`: 1e300 is outside"),
        "{e}"
    );
    let mut lf = crate::LaunchFile::parse(&text.replace("1e300", "60"), std::path::Path::new("m.toml"))
        .expect("parses");
    let r = lf.services[0].restart_rules();
    assert_eq!(
        (r.mode, r.max_restarts, r.window, r.backoff_ms),
        (Restart::OnFailure, 5, Duration::from_secs(60), 7)
    );
    // Built by a program rather than read from a file, a window too long for a Duration never
    // expires.
    lf.services[0].restart_window_s = 1e300;
    assert_eq!(lf.services[0].restart_rules().window, Duration::MAX);
}
