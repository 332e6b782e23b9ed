//! A live realtime mission: three `python -m harvey_client echo` subscribers and the library
//! itself, started with the launch, then what they received compared with the recording.

use std::collections::BTreeMap;
use std::process::{Command, Output, Stdio};
use std::time::Duration;

use harvey_msgs::{FrameHeader, Odometry, SonarRing};
use serde_json::{Value, json};

use crate::common;
use crate::compare::Compare;
use crate::text;
use crate::venv::{client, python};

fn json_lines(out: &Output) -> Vec<Value> {
    assert!(out.status.success(), "{}", text(out));
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect()
}

/// Uses the library: three mission statuses through `subscribe()` (their `seq`s as a JSON list),
/// then `sonar/ring` opened as if it carried odometry.
const LIBRARY: &str = r#"
import json, sys
import harvey_client as hc
from harvey_client.topics import STATE, Topic

prefix = sys.argv[1]
print(json.dumps([m.header.seq for m in hc.subscribe(prefix, "executive/status", count=3, timeout_s=30, wait_s=60)]))
try:
    hc.Subscription(prefix, Topic("sonar/ring", hc.Odometry, STATE))
except hc.IncompatibleTopic as e:
    print(f"IncompatibleTopic: {e}")
"#;

/// The pixels of a frame without row padding.
fn tight(h: &FrameHeader, pixels: &[u8]) -> Vec<u8> {
    let row = (h.width_px * h.encoding().unwrap().bytes_per_pixel()) as usize;
    pixels
        .chunks(h.stride_bytes as usize)
        .take(h.height_px as usize)
        .flat_map(|r| &r[..row])
        .copied()
        .collect()
}

#[test]
fn python_receives_what_the_recorder_records_from_a_realtime_run() {
    let python = python();
    let (prefix, dir) = (common::unique_prefix("py"), common::scratch("py"));
    let log = std::fs::File::create(dir.join("harvey-run.log")).unwrap();
    let mut run =
        common::harvey(&["run", "--realtime", "--prefix", &prefix, "--run-dir", dir.to_str().unwrap()])
            .stdout(log.try_clone().unwrap())
            .stderr(log)
            .spawn()
            .expect("harvey run");

    // Three subscribers at once, each in its own process, started with the launch: each waits
    // for the domain and its topic to appear (--wait-s), then for its messages (--timeout-s).
    let frames_dir = dir.join("frames");
    let echo = |topic: &str, count: &str| {
        let mut c = Command::new(python);
        c.args(["-m", "harvey_client", "echo", &prefix, topic, "--count", count, "--json"])
            .args(["--wait-s", "60", "--timeout-s", "60", "--save-frames", frames_dir.to_str().unwrap()])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        c.spawn().expect("python")
    };
    let (rings, odometry, frames) =
        (echo("sonar/ring", "40"), echo("odometry", "40"), echo("camera/frame", "5"));
    // The library itself, as its README uses it: `subscribe()`, and the refusal of a topic
    // opened with another type than the launch's.
    let library = Command::new(python)
        .args(["-c", LIBRARY, &prefix])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("python");
    let rings = json_lines(&rings.wait_with_output().unwrap());
    let odometry = json_lines(&odometry.wait_with_output().unwrap());
    let frames = json_lines(&frames.wait_with_output().unwrap());
    assert_eq!((rings.len(), odometry.len(), frames.len()), (40, 40, 5));
    let library = library.wait_with_output().unwrap();
    let said = text(&library);
    assert!(library.status.success(), "{said}");
    let statuses: Vec<u64> = serde_json::from_str(said.lines().next().unwrap()).unwrap();
    assert!(statuses.len() == 3 && statuses.windows(2).all(|w| w[0] < w[1]), "{said}");
    assert!(
        said.contains("IncompatibleTopic: topic `sonar/ring`") && said.contains("(IncompatibleTypes)"),
        "{said}"
    );

    // While the launch runs: the errors of a wrong domain, topic, or topic the domain lacks.
    let wrong = |args: &[&str], says: &str| {
        let out = client(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{}", text(&out));
        assert!(String::from_utf8_lossy(&out.stderr).contains(says), "{}", text(&out));
    };
    let other = format!("{prefix}x");
    wrong(
        &["echo", &other, "sonar/ring", "--count", "1"],
        &format!("no Harvey domain with prefix `{other}`"),
    );
    wrong(
        &["echo", &prefix, "sonar/rings", "--count", "1"],
        "no topic `sonar/rings` in Harvey's topic table",
    );
    wrong(
        &["echo", &prefix, "clock/nobody", "--count", "1"],
        &format!("domain `{prefix}` has no topic `clock/nobody`"),
    );
    assert!(common::shm_leftovers(&other).is_empty(), "the wrong prefix left shared memory behind");

    common::signal(&run, libc::SIGINT);
    common::wait_exit(&mut run, Duration::from_secs(60));
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());

    // What the recorder recorded.
    let mcap = std::fs::read(dir.join("run.mcap")).expect("recording");
    let (mut rec_rings, mut rec_odometry, mut rec_frames) =
        (BTreeMap::new(), BTreeMap::new(), BTreeMap::new());
    for m in mcap::MessageStream::new(&mcap).expect("mcap") {
        let m = m.expect("message");
        match m.channel.topic.as_str() {
            "/sonar/ring" => {
                let r: SonarRing = harvey_cdr::decode(&m.data).expect("ring");
                rec_rings.insert(r.header.seq, r);
            }
            "/odometry" => {
                let o: Odometry = harvey_cdr::decode(&m.data).expect("odometry");
                rec_odometry.insert(o.header.seq, o);
            }
            "/camera/frame" => {
                let (h, pixels) = harvey_cdr::decode_image(&m.data).expect("image");
                rec_frames.insert(h.stamp_ns, (h, tight(&h, pixels)));
            }
            _ => {}
        }
    }

    let mut cmp = Compare::default();
    let mut last = None;
    for r in &rings {
        assert_eq!(r["type"], "harvey_msgs/SonarRing");
        let seq = r["msg"]["header"]["seq"].as_u64().unwrap();
        assert!(last < Some(seq), "sonar/ring out of order: {seq} after {last:?}");
        last = Some(seq);
        let recorded =
            rec_rings.get(&seq).unwrap_or_else(|| panic!("sonar/ring {seq} is not in the recording"));
        cmp.ring(&r["msg"], recorded);
    }
    let mut last = None;
    for o in &odometry {
        assert_eq!(o["type"], "harvey_msgs/Odometry");
        let seq = o["msg"]["header"]["seq"].as_u64().unwrap();
        assert!(last < Some(seq), "odometry out of order: {seq} after {last:?}");
        last = Some(seq);
        let recorded =
            rec_odometry.get(&seq).unwrap_or_else(|| panic!("odometry {seq} is not in the recording"));
        cmp.odometry(&o["msg"], recorded);
    }
    let mut pixels = 0;
    for f in &frames {
        let h = &f["header"];
        let stamp = h["stamp_ns"].as_u64().unwrap();
        let (rh, rp) =
            rec_frames.get(&stamp).unwrap_or_else(|| panic!("the frame of {stamp} ns is not recorded"));
        cmp.int("frame width_px", &h["width_px"], rh.width_px.into());
        cmp.int("frame height_px", &h["height_px"], rh.height_px.into());
        cmp.int("frame stride_bytes", &h["stride_bytes"], rh.stride_bytes.into());
        cmp.int("frame encoding", &h["encoding"], rh.encoding.into());
        assert_eq!(f["encoding"], "mono8");
        assert_eq!(f["shape"], json!([rh.height_px, rh.width_px]));
        let got = std::fs::read(f["file"].as_str().unwrap()).unwrap();
        assert_eq!(got.len(), rp.len(), "frame {stamp}");
        assert!(got == *rp, "the pixels of frame {stamp} differ from the recording's");
        assert!(got.iter().any(|&b| b != got[0]), "frame {stamp} is blank");
        pixels += got.len();
    }
    println!(
        "python_client: {} rings, {} odometry messages ({} fields), {} frames ({pixels} pixel bytes) equal the recording's",
        rings.len(),
        odometry.len(),
        cmp.fields,
        frames.len()
    );
    assert!(cmp.mismatches.is_empty(), "{} mismatches:\n{}", cmp.mismatches.len(), cmp.mismatches.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}
