//! The vision workers' request protocol on rendered frames: every algorithm answers with the
//! frame's seq and stamp; bad requests get an error status; two workers sharing the requests
//! give the answers one worker gives; and answering a frame allocates nothing once warm.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use harvey_msgs::{Encoding, FrameHeader, Pose2, VisionAlgorithm, VisionRequest, VisionResult, VisionStatus};
use harvey_render::Renderer;
use harvey_vision_workers::dispatch::Dispatcher;
use harvey_world::World;

/// Counts the allocations each thread makes (tests run side by side in threads).
struct Counting;
thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}
// SAFETY: forwards to the system allocator, only counting.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(p, l) }
    }
}
#[global_allocator]
static GLOBAL: Counting = Counting;

fn hallway() -> World {
    harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads")
}

const POSE: Pose2 = Pose2::new(8.0, 0.0, 0.3);

fn frame(w: &World, seq: u64) -> (FrameHeader, Vec<u8>) {
    let mut r = Renderer::new(w, 640, 480, Encoding::Mono8);
    let mut px = vec![0u8; r.frame_bytes()];
    r.render(w, POSE, &mut px).expect("renders");
    (FrameHeader::new(seq, seq * 100_000_000, 640, 480, Encoding::Mono8), px)
}

fn request(id: u32, algorithm: VisionAlgorithm) -> VisionRequest {
    VisionRequest { request_id: id, algorithm: algorithm as u32, ..Default::default() }
}

fn sign_index(w: &World) -> u32 {
    w.landmarks.iter().position(|l| l.name == "office-sign").expect("sign") as u32
}

fn requests(w: &World) -> Vec<VisionRequest> {
    let expected = POSE;
    let mut lines = request(3, VisionAlgorithm::LineFinder);
    lines.params[4..6].copy_from_slice(&[80.0, 100.0]); // near-vertical lines only
    let mut regions = request(4, VisionAlgorithm::RegionSegmenter);
    regions.params[..3].copy_from_slice(&[0.0, 90.0, 50.0]);
    let mut windowed = request(5, VisionAlgorithm::Moravec);
    windowed.window_px = [200.0, 100.0, 440.0, 380.0];
    let mut sign = request(6, VisionAlgorithm::Correlate);
    (sign.landmark_index, sign.expected) = (sign_index(w), expected);
    // Its lower-left corner, where the sign meets the wall: a vertex (000 §5.2).
    sign.params[..5].copy_from_slice(&[24.0, 0.9, -0.2, 0.0, -0.15]);
    vec![request(2, VisionAlgorithm::Moravec), lines, regions, windowed, sign]
}

fn status(r: &VisionResult) -> VisionStatus {
    VisionStatus::from_raw(r.status).expect("a known status")
}

#[test]
fn every_algorithm_answers_with_the_frames_seq_and_stamp() {
    let w = hallway();
    let (h, px) = frame(&w, 7);
    let mut d = Dispatcher::new(w.clone());
    for req in requests(&w) {
        let r = d.answer(&h, &px, &req);
        assert_eq!((r.frame_seq, r.header.stamp_ns, r.request_id), (7, 700_000_000, req.request_id));
        assert_eq!(status(&r), VisionStatus::Found, "request {}: {r:?}", req.request_id);
        assert!(r.count > 0 && r.count <= r.found);
    }
    // Near-vertical lines are near-vertical; the windowed corners lie in the window.
    let lines = d.answer(&h, &px, &requests(&w)[1]);
    for i in &lines.items[..lines.count as usize] {
        let v = i.values;
        assert!((v[2] - v[0]).abs() <= (v[3] - v[1]).abs() * 0.2, "not vertical: {v:?}");
    }
    let corners = d.answer(&h, &px, &requests(&w)[3]);
    for i in &corners.items[..corners.count as usize] {
        assert!(
            (200.0..440.0).contains(&i.values[0]) && (100.0..380.0).contains(&i.values[1]),
            "{:?}",
            i.values
        );
    }
    // The sign's template, from the pose the frame was taken at, lands on its projection.
    let sign = d.answer(&h, &px, &requests(&w)[4]);
    let v = sign.items[0].values;
    assert!((v[0] - v[3]).hypot(v[1] - v[4]) < 1.0 && v[2] > 0.99, "{v:?}");
}

#[test]
fn bad_requests_get_error_results() {
    let w = hallway();
    let (h, px) = frame(&w, 1);
    let mut d = Dispatcher::new(w.clone());
    let mut outside = request(1, VisionAlgorithm::Moravec);
    outside.window_px = [600.0, 400.0, 700.0, 480.0];
    let mut unknown = request(2, VisionAlgorithm::Correlate);
    unknown.landmark_index = 999;
    let mut off_image = request(3, VisionAlgorithm::Correlate);
    off_image.landmark_index = sign_index(&w);
    off_image.expected = Pose2 { x_m: 8.0, y_m: 0.0, heading_rad: std::f64::consts::PI }; // looking away
    let mut regions = request(4, VisionAlgorithm::RegionSegmenter);
    regions.params[..2].copy_from_slice(&[200.0, 100.0]);
    let bogus = VisionRequest { request_id: 5, algorithm: 77, ..Default::default() };
    let mut nan = request(6, VisionAlgorithm::LineFinder);
    nan.window_px = [f32::NAN, 0.0, 10.0, 10.0];
    let cases = [
        (outside, VisionStatus::WindowOutsideFrame),
        (unknown, VisionStatus::UnknownLandmark),
        (off_image, VisionStatus::BadTemplate),
        (regions, VisionStatus::BadParameter),
        (bogus, VisionStatus::UnknownAlgorithm),
        (nan, VisionStatus::WindowOutsideFrame),
    ];
    for (req, want) in cases {
        let r = d.answer(&h, &px, &req);
        assert_eq!((status(&r), r.count), (want, 0), "request {}", req.request_id);
    }
    // A frame whose bytes do not fill its header.
    let r = d.answer(&h, &px[..1000], &request(7, VisionAlgorithm::Moravec));
    assert_eq!(status(&r), VisionStatus::BadFrame);
    // And the worker still answers good requests afterwards.
    assert_eq!(status(&d.answer(&h, &px, &requests(&w)[0])), VisionStatus::Found);
}

#[test]
fn two_workers_sharing_the_requests_answer_as_one_and_allocate_nothing_once_warm() {
    let w = hallway();
    let (h1, px1) = frame(&w, 1);
    let (h2, px2) = frame(&w, 2);
    let reqs = requests(&w);
    let mut one = Dispatcher::new(w.clone());
    let mut shards = [Dispatcher::new(w.clone()), Dispatcher::new(w.clone())];
    let strip = |mut r: VisionResult| {
        r.header.seq = 0; // each worker numbers its own results
        r
    };
    for (h, px) in [(&h1, &px1), (&h2, &px2)] {
        for req in &reqs {
            let alone = strip(one.answer(h, px, req));
            let shared = strip(shards[(req.request_id % 2) as usize].answer(h, px, req));
            assert_eq!(alone, shared, "request {}", req.request_id);
        }
    }
    // The counter counts: a fresh worker's first answers grow its buffers.
    let cold = ALLOCATIONS.with(Cell::get);
    let mut fresh = Dispatcher::new(w.clone());
    for req in &reqs {
        let _ = fresh.answer(&h2, &px2, req);
    }
    assert!(ALLOCATIONS.with(Cell::get) > cold, "the counting allocator sees allocations");
    // Warm now: a third frame's answers allocate nothing.
    let before = ALLOCATIONS.with(Cell::get);
    let mut out = [VisionResult::default(); 8];
    for (o, req) in out.iter_mut().zip(&reqs) {
        *o = one.answer(&h2, &px2, req);
    }
    let after = ALLOCATIONS.with(Cell::get);
    assert_eq!(after - before, 0, "allocations while answering a frame");
    assert!(out[..reqs.len()].iter().all(|r| status(r) == VisionStatus::Found));
}

#[test]
fn phototropic_and_activity_requests() {
    let w = hallway();
    let (h, px) = frame(&w, 1);
    let mut d = Dispatcher::new(w.clone());
    let light = d.answer(&h, &px, &request(8, VisionAlgorithm::Phototropic));
    assert_eq!(status(&light), VisionStatus::Found, "{light:?}");
    let [cx, cy] = [light.items[0].values[0] as usize, light.items[0].values[1] as usize];
    let brightest = *px.iter().max().expect("pixels");
    assert!(px[cy * 640 + cx] + 20 >= brightest, "the centroid lies in the bright region");
    // Activity (a standing request): nothing moves between two identical frames, then the view
    // changes and the activity is found.
    let mut act = request(9, VisionAlgorithm::Activity);
    (act.standing, act.params[0], act.params[1]) = (1, 1.0, 15.0);
    assert_eq!(status(&d.answer(&h, &px, &act)), VisionStatus::NotFound, "one frame: nothing yet");
    assert_eq!(status(&d.answer(&h, &px, &act)), VisionStatus::NotFound, "no motion");
    let mut moved = Renderer::new(&w, 640, 480, Encoding::Mono8);
    let mut px2 = vec![0u8; moved.frame_bytes()];
    moved.render(&w, Pose2 { x_m: POSE.x_m + 0.3, ..POSE }, &mut px2).expect("renders");
    let r = d.answer(&FrameHeader::new(3, 300_000_000, 640, 480, Encoding::Mono8), &px2, &act);
    assert_eq!(status(&r), VisionStatus::Found, "{r:?}");
    assert!(r.items[0].values[2] > 0.0);
}

#[test]
fn the_dock_is_recognised_on_the_bus_with_its_posts_heights() {
    let w = harvey_world::load_str(include_str!("../../../worlds/dock.toml"), "dock").expect("loads");
    let mut r = Renderer::new(&w, 640, 480, Encoding::Mono8);
    let mut px = vec![0u8; r.frame_bytes()];
    // 3.6 m from the dock's face, 0.4 m to its right, turned 8 degrees towards it.
    let pose = Pose2::new(10.0, -0.4, 8f64.to_radians());
    r.render(&w, pose, &mut px).expect("renders");
    let h = FrameHeader::new(1, 100_000_000, 640, 480, Encoding::Mono8);
    let mut d = Dispatcher::new(w.clone());
    let f = w.camera.focal_for(640);
    // Scale hypotheses for 2.6-4.6 m: 0.5 m (a model unit) at those depths.
    let mut dock = request(11, VisionAlgorithm::Dock);
    dock.params[..5].copy_from_slice(&[(f * 0.5 / 4.6) as f32, (f * 0.5 / 2.6) as f32, 5.0, 0.0, 0.6]);
    let found = d.answer(&h, &px, &dock);
    assert_eq!(status(&found), VisionStatus::Found, "{found:?}");
    // Warm now: the same request again allocates nothing (the Hough space is kept).
    let before = ALLOCATIONS.with(Cell::get);
    let again = d.answer(&h, &px, &dock);
    assert_eq!(ALLOCATIONS.with(Cell::get) - before, 0, "allocations while finding the dock");
    assert_eq!(again.items[0], found.items[0]);
    let [u, v, certainty, scale, left, right] = found.items[0].values;
    let centre = w.camera.project(640, 480, pose, [13.6, 0.0, 0.45]).expect("in front");
    assert!((u as f64 - centre[0]).abs() < 3.0 && (v as f64 - centre[1]).abs() < 3.0, "{found:?} {centre:?}");
    assert!(certainty >= 0.6 && (60.0..100.0).contains(&scale), "{found:?}");
    // Seen from the right, the left post is further and looks shorter; each within a pixel or
    // two of its projection.
    let height = |y: f64| {
        let top = w.camera.project(640, 480, pose, [13.6, y, 0.70]).expect("top");
        let foot = w.camera.project(640, 480, pose, [13.6, y, 0.20]).expect("foot");
        foot[1] - top[1]
    };
    assert!(left < right, "{found:?}");
    assert!(
        (f64::from(left) - height(0.5)).abs() < 2.5 && (f64::from(right) - height(-0.5)).abs() < 2.5,
        "{found:?}"
    );
    // Looking away from the dock: not found.
    r.render(&w, Pose2::new(10.0, -0.4, 1.5), &mut px).expect("renders");
    assert_eq!(status(&d.answer(&h, &px, &dock)), VisionStatus::NotFound);
    dock.params[0] = f32::NAN;
    assert_eq!(status(&d.answer(&h, &px, &dock)), VisionStatus::BadParameter);
}

#[test]
fn coded_poles_are_recognised_with_their_range_and_code() {
    let mut w = harvey_world::load_str(include_str!("../../../worlds/arena.toml"), "arena").expect("loads");
    let poles = w.place_poles(3).expect("room");
    let mut d = Dispatcher::new(w.clone());
    let mut r = Renderer::new(&w, 640, 480, Encoding::Mono8);
    let mut px = vec![0u8; r.frame_bytes()];
    let h = FrameHeader::new(1, 100_000_000, 640, 480, Encoding::Mono8);
    let (mut seen, mut with_poles) = (0, None);
    // From the start, looking round in steps of half the field of view: every pole in view and
    // unhidden within 10 m is found with its code and its range to within 3 %.
    for k in 0..12 {
        let pose = Pose2 { heading_rad: f64::from(k) * 30f64.to_radians(), ..w.start };
        r.render(&w, pose, &mut px).expect("renders");
        let res = d.answer(&h, &px, &request(12, VisionAlgorithm::Poles));
        if res.count > 0 {
            with_poles.get_or_insert(pose);
        }
        for item in &res.items[..res.count as usize] {
            let [u, range, code, ..] = item.values;
            let p = poles.iter().find(|p| p.code == code as u32).expect("a real code");
            let depth =
                (p.at[0] - pose.x_m) * pose.heading_rad.cos() + (p.at[1] - pose.y_m) * pose.heading_rad.sin();
            assert!(
                (f64::from(range) / depth - 1.0).abs() < 0.03,
                "pole {code}: {range} m against {depth} m"
            );
            let col = w.camera.project(640, 480, pose, [p.at[0], p.at[1], 1.0]).expect("in front")[0];
            assert!((f64::from(u) - col).abs() < 3.0, "pole {code} at {u}, projects to {col}");
            seen += 1;
        }
    }
    assert!(seen >= 8, "{seen} sightings");
    // Warm now: another look at poles allocates nothing.
    r.render(&w, with_poles.expect("a look with poles"), &mut px).expect("renders");
    let before = ALLOCATIONS.with(Cell::get);
    let again = d.answer(&h, &px, &request(12, VisionAlgorithm::Poles));
    assert_eq!(ALLOCATIONS.with(Cell::get) - before, 0, "allocations while finding poles");
    assert_eq!(status(&again), VisionStatus::Found, "{again:?}");
    let hallway = Dispatcher::new(hallway()).answer(&h, &px, &request(12, VisionAlgorithm::Poles));
    assert_eq!(status(&hallway), VisionStatus::BadParameter, "no [poles] in the hallway");
}
