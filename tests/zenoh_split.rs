//! `missions/default-split.toml` over two bus domains (two prefixes, which never see each other
//! over iceoryx2) joined only by the two Zenoh bridges of a split launch on
//! `tcp/127.0.0.1:<free port>` (issue 16): the recording is the one the mission makes on one
//! host, deterministic or in real time; either host's bridge killed mid-run comes back and the
//! recording is still identical; a host that never joins is named.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::process::Stdio;
use std::time::Duration;

use harvey_bus::Bus;
use harvey_msgs::topics;

/// `harvey diff`'s verdict on two recordings.
fn diff(a: &std::path::Path, b: &std::path::Path) -> String {
    let out = common::harvey(&["diff", a.to_str().expect("utf8"), b.to_str().expect("utf8")])
        .output()
        .expect("diff");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// `missions/default-split.toml` run over two bus domains joined only by the two bridges: the
/// gpu host's share started first, then the main host's, which must reach the goal and end the
/// other's launch too. Returns the main host's run folder (to remove) after checking both
/// domains' shared memory is gone.
fn run_split(tag: &str, how: &[&str]) -> common::Scratch {
    let mission = "missions/default-split.toml";
    let (pa, pb) = (common::unique_prefix(&format!("{tag}a")), common::unique_prefix(&format!("{tag}b")));
    let (main_dir, gpu_dir) =
        (common::scratch(&format!("{tag}-main")), common::scratch(&format!("{tag}-gpu")));
    let at = format!("tcp/127.0.0.1:{}", common::free_port());
    let mut gpu =
        common::harvey(&["launch", mission, "--host", "gpu", "--prefix", &pb, "--zenoh-listen", &at])
            .args(how)
            .args(["--run-dir", gpu_dir.to_str().expect("utf8")])
            .stdout(Stdio::null())
            .spawn()
            .expect("the gpu host's share");
    let main = common::harvey(&["run", mission, "--host", "main", "--prefix", &pa, "--zenoh-connect", &at])
        .args(how)
        .args(["--run-dir", main_dir.to_str().expect("utf8")])
        .output()
        .expect("the main host's share");
    let stdout = String::from_utf8_lossy(&main.stdout);
    assert!(main.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&main.stderr));
    assert!(stdout.contains("goal reached"), "{stdout}");
    assert!(
        common::wait_exit(&mut gpu, Duration::from_secs(60)).success(),
        "the gpu host's launch ends cleanly"
    );
    for p in [&pa, &pb] {
        assert_eq!(common::shm_leftovers(p), Vec::<String>::new());
    }
    std::fs::remove_dir_all(&gpu_dir).ok();
    main_dir
}

#[test]
fn a_mission_split_over_two_hosts_records_what_it_records_on_one() {
    let main_dir = run_split("zsplit", &[]);
    let one = common::run_mission("missions/default-split.toml", "zenoh-split-one");
    assert!(one.status.success(), "{}", one.stdout);
    let verdict = diff(&one.dir.join("run.mcap"), &main_dir.join("run.mcap"));
    assert!(verdict.starts_with("identical"), "split over two hosts against one host: {verdict}");
    std::fs::remove_dir_all(&main_dir).ok();
}

#[test]
fn a_mission_split_over_two_hosts_runs_in_real_time_too() {
    let main_dir = run_split("zlive", &["--realtime"]);
    // The gpu host's services were heard on the main host: the vision workers' detections and
    // the UMS's maps, on about every frame and tick of the 26 s run.
    let recording = harvey_recording::Recording::open(&main_dir.join("run.mcap")).expect("recording");
    let (mut detections, mut maps) = (0, 0);
    for m in recording.messages().expect("messages") {
        match m.expect("reads").topic() {
            "vision/detections" => detections += 1,
            "ums/map" => maps += 1,
            _ => {}
        }
    }
    assert!(detections > 200 && maps > 400, "{detections} detections, {maps} maps from host gpu");
    std::fs::remove_dir_all(&main_dir).ok();
}

/// Waits until `sim/truth` in the bus domain `prefix` passes `at_ns` of the run's time, then
/// SIGKILLs the domain's `service`; returns its pid, or `None` if the launch ended first.
fn kill_when(prefix: &str, service: &str, at_ns: u64, running: impl Fn() -> bool) -> Option<i32> {
    let bridge = || {
        harvey_bus::live_nodes(prefix)
            .unwrap_or_default()
            .into_iter()
            .find(|n| n.alive && n.name == service)
            .map(|n| n.pid)
    };
    while bridge().is_none() {
        if !running() {
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let bus = Bus::join_with_prefix("test-killer", prefix).expect("bus");
    let truth = bus.subscriber(topics::SIM_TRUTH).expect("sim/truth");
    loop {
        if truth.latest().expect("truth").is_some_and(|t| t.header.stamp_ns >= at_ns) {
            break;
        }
        if !running() {
            return None;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let pid = bridge()?;
    // SAFETY: kill(2) on a process of this test's launch.
    unsafe { libc::kill(pid, libc::SIGKILL) };
    Some(pid)
}

/// A service SIGKILLed on a host when the run's time passes a stamp (ns).
type Kill<'a> = (&'a str, &'a str, u64);

/// `default-split` over two domains with services SIGKILLed as `kills` say (in time order);
/// checks both shares end well, each killed service was restarted by its host's supervisor, and
/// nothing is left in shared memory. The main host's run folder.
fn split_with_kills(tag: &str, kills: &[Kill]) -> common::Scratch {
    let mission = "missions/default-split.toml";
    let (pa, pb) = (common::unique_prefix(&format!("{tag}a")), common::unique_prefix(&format!("{tag}b")));
    let (main_dir, gpu_dir) =
        (common::scratch(&format!("{tag}-main")), common::scratch(&format!("{tag}-gpu")));
    let at = format!("tcp/127.0.0.1:{}", common::free_port());
    let log = |dir: &std::path::Path, name: &str| std::fs::File::create(dir.join(name)).expect("log");
    let mut gpu =
        common::harvey(&["launch", mission, "--host", "gpu", "--prefix", &pb, "--zenoh-listen", &at])
            .args(["--run-dir", gpu_dir.to_str().expect("utf8")])
            .stdout(Stdio::null())
            .stderr(log(&gpu_dir, "stderr.log"))
            .spawn()
            .expect("the gpu host's share");
    let mut main =
        common::harvey(&["run", mission, "--host", "main", "--prefix", &pa, "--zenoh-connect", &at])
            .args(["--run-dir", main_dir.to_str().expect("utf8")])
            .stdout(log(&main_dir, "stdout.log"))
            .stderr(log(&main_dir, "stderr.log"))
            .spawn()
            .expect("the main host's share");
    let main_pid = main.id();
    // Until `harvey run` exits (a zombie until waited for).
    let running =
        move || std::fs::read_to_string(format!("/proc/{main_pid}/stat")).is_ok_and(|s| !s.contains(") Z "));
    let killed: Vec<Option<i32>> = kills
        .iter()
        .map(|&(host, service, at_ns)| {
            kill_when(if host == "main" { &pa } else { &pb }, service, at_ns, running)
        })
        .collect();
    let status = common::wait_exit(&mut main, Duration::from_secs(300));
    let read = |p: std::path::PathBuf| std::fs::read_to_string(p).expect("log");
    let (stdout, stderr) = (read(main_dir.join("stdout.log")), read(main_dir.join("stderr.log")));
    let gpu_log = read(gpu_dir.join("stderr.log"));
    assert!(status.success() && stdout.contains("goal reached"), "{stdout}\n{stderr}\n--- gpu:\n{gpu_log}");
    assert!(common::wait_exit(&mut gpu, Duration::from_secs(60)).success(), "{gpu_log}");
    assert!(killed.iter().all(Option::is_some), "every kill landed mid-run: {kills:?} {killed:?}");
    for (host, service, _) in kills {
        let log = if *host == "main" { &stderr } else { &gpu_log };
        let said =
            |what: &str| log.lines().any(|l| l.contains(what) && l.contains(&format!("service={service}")));
        assert!(
            said("exited with SIGKILL: restart") && said("restarted"),
            "the {host} host's supervisor restarted its killed {service}:\n{log}"
        );
    }
    if kills.iter().any(|(h, s, _)| (*h, *s) == ("gpu", "zenoh-bridge")) {
        assert!(gpu_log.contains("restarted: asking host main for the tick after"), "{gpu_log}");
    }
    for p in [&pa, &pb] {
        assert_eq!(common::shm_leftovers(p), Vec::<String>::new());
    }
    main_dir
}

/// Item 5 of issue 16: each host's bridge SIGKILLed mid-run, in either order and at times that
/// land in different places of its turn, is restarted by its supervisor and the chain resumes
/// where it was: the mission reaches its goal and the recording is the one the mission makes on
/// one host, every time. So with the gpu host's own parties killed: the bridge there re-offers
/// what it published to them.
#[test]
fn a_bridge_killed_mid_run_on_either_host_comes_back_and_the_recording_is_identical() {
    let s = 1_000_000_000;
    let one = common::run_mission("missions/default-split.toml", "zenoh-kill-one");
    assert!(one.status.success(), "{}", one.stdout);
    let bridge = "zenoh-bridge";
    let plans: [&[Kill]; 4] = [
        &[("main", bridge, 6 * s), ("gpu", bridge, 14 * s)],
        &[("gpu", bridge, 5 * s + 230_000_000), ("main", bridge, 11 * s + 770_000_000)],
        &[
            ("main", bridge, 9 * s + 310_000_000),
            ("gpu", bridge, 9 * s + 960_000_000),
            ("main", bridge, 20 * s),
        ],
        &[("gpu", "vision-workers", 7 * s + 50_000_000), ("gpu", "ums", 15 * s + 420_000_000)],
    ];
    for (i, kills) in plans.iter().enumerate() {
        let main_dir = split_with_kills(&format!("zk{i}"), kills);
        let verdict = diff(&one.dir.join("run.mcap"), &main_dir.join("run.mcap"));
        assert!(verdict.starts_with("identical"), "kills {kills:?} against one host: {verdict}");
    }
}

#[test]
fn a_host_that_never_joins_is_named() {
    let dir = common::scratch("zenoh-split-alone");
    let prefix = common::unique_prefix("zsn");
    let at = format!("tcp/127.0.0.1:{}", common::free_port());
    let out = common::harvey(&["run", "missions/default-split.toml", "--host", "main", "--prefix", &prefix])
        .args(["--zenoh-listen", &at, "--run-dir", dir.to_str().expect("utf8")])
        .output()
        .expect("runs");
    let all = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(!out.status.success(), "{all}");
    assert!(all.contains("host gpu never joined"), "{all}");
    let unknown =
        common::harvey(&["launch", "missions/default-split.toml", "--host", "tpu", "--zenoh-listen", &at])
            .output()
            .expect("runs");
    let err = String::from_utf8_lossy(&unknown.stderr);
    assert!(!unknown.status.success() && err.contains("none on `tpu`"), "{err}");
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    std::fs::remove_dir_all(&dir).ok();
}
