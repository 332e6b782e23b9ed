//! Tests of the class I recogniser (`LineLandmarks`) on drawn frames: bearings, ambiguity, the
//! predicted look, noise and blur.

use super::*;
use harvey_msgs::Encoding;

fn frame(edges: &[(u32, u8)]) -> Vec<u8> {
    (0..64 * 48)
        .map(|i| {
            let u = i % 64;
            edges.iter().rev().find(|(at, _)| u >= *at).map_or(50, |(_, v)| *v)
        })
        .collect()
}

fn expect(u0: f32, u1: f32) -> Expectation {
    Expectation {
        landmark_index: 4,
        class: 1,
        window_px: [u0, 10.0, u1, 40.0],
        width_px: 64,
        height_px: 48,
        ..Default::default()
    }
}

#[test]
fn one_edge_in_the_window_gives_its_bearing() {
    let h = FrameHeader::new(9, 123, 64, 48, Encoding::Mono8);
    let mut r = LineLandmarks::new(55.4, 10.0);
    let s = r.recognise(&h, &frame(&[(40, 200)]), &expect(30.0, 50.0)).expect("an answer");
    assert_eq!(
        (s.kind, s.landmark_index, s.frame_seq, s.header.stamp_ns),
        (SightingKind::Bearing as u32, 4, 9, 123)
    );
    assert!((s.a - ((32.0 - 40.0) / 55.4f64).atan()).abs() < 1e-12, "{}", s.a);
}

#[test]
fn no_edge_is_not_found_and_two_like_edges_are_no_answer() {
    let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
    let mut r = LineLandmarks::new(55.4, 10.0);
    let none = r.recognise(&h, &frame(&[(40, 200)]), &expect(5.0, 30.0)).expect("an answer");
    assert_eq!(none.kind, SightingKind::NotFound as u32);
    assert!(r.recognise(&h, &frame(&[(35, 150), (45, 250)]), &expect(30.0, 50.0)).is_none(), "ambiguous");
    // A dominant edge beside a weak one is still recognised.
    let s = r.recognise(&h, &frame(&[(35, 65), (45, 250)]), &expect(30.0, 50.0)).expect("dominant");
    assert_eq!(s.kind, SightingKind::Bearing as u32);
    let other_size = Expectation { width_px: 640, ..expect(30.0, 50.0) };
    assert!(r.recognise(&h, &frame(&[]), &other_size).is_none());
}

#[test]
fn the_predicted_look_tells_the_landmark_from_a_look_alike_stepping_the_other_way() {
    // A bright door between columns 35 and 45: its two jambs step opposite ways, alike in
    // strength, so without a prediction the window is ambiguous.
    let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
    let f = frame(&[(35, 200), (45, 50)]);
    let mut r = LineLandmarks::new(55.4, 10.0);
    assert!(r.recognise(&h, &f, &expect(25.0, 55.0)).is_none(), "ambiguous");
    for (contrast, column) in [(0.4, 35.0), (-0.4, 45.0)] {
        let e = Expectation { contrast: [contrast; 4], ..expect(25.0, 55.0) };
        let s = r.recognise(&h, &f, &e).expect("an answer");
        assert_eq!(s.kind, SightingKind::Bearing as u32);
        assert!((s.a - bearing(column)).abs() < 1e-9, "{contrast}: {} for {column}", s.a);
    }
    // Only the look-alike in the window: not found, never taken for the landmark.
    let e = Expectation { contrast: [0.4; 4], ..expect(40.0, 55.0) };
    assert_eq!(r.recognise(&h, &f, &e).expect("an answer").kind, SightingKind::NotFound as u32);
}

#[test]
fn a_faint_look_keeps_its_look_alike_a_rival_and_no_look_refuses_nothing() {
    // The bright door of the test above, its east jamb (column 45) stepping down.
    let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
    let f = frame(&[(35, 200), (45, 50)]);
    let mut r = LineLandmarks::new(55.4, 10.0);
    // A faint look (a landmark the map predicts barely steps up): the jamb stepping down is
    // neither dropped, so the window stays ambiguous, nor taken when it is alone.
    let faint = Expectation { contrast: [0.05; 4], ..expect(25.0, 55.0) };
    assert!(r.recognise(&h, &f, &faint).is_none(), "ambiguous");
    let alone = Expectation { contrast: [0.05; 4], ..expect(40.0, 55.0) };
    assert!(r.recognise(&h, &f, &alone).is_none(), "never taken");
    // Under `faint_look` there is no look to go by: the one edge in the window is the answer.
    for look in [0.0, 0.01] {
        let none = Expectation { contrast: [look; 4], ..expect(40.0, 55.0) };
        let s = r.recognise(&h, &f, &none).expect("an answer");
        assert_eq!(s.kind, SightingKind::Bearing as u32, "look {look}");
        assert!((s.a - bearing(45.0)).abs() < 1e-9, "look {look}: {}", s.a);
    }
}

#[test]
fn a_frame_whose_rows_do_not_fit_its_stride_is_no_answer_not_a_panic() {
    let mut r = LineLandmarks::new(55.4, 10.0);
    let f = frame(&[(40, 200)]);
    for stride in [0, 1, 63] {
        let h = FrameHeader { stride_bytes: stride, ..FrameHeader::new(1, 0, 64, 48, Encoding::Mono8) };
        assert!(r.recognise(&h, &f, &expect(30.0, 50.0)).is_none(), "stride {stride}");
    }
    // An rgb8 header over mono bytes: three bytes a pixel do not fit a 64-byte row.
    let rgb = FrameHeader { stride_bytes: 64, ..FrameHeader::new(1, 0, 64, 48, Encoding::Rgb8) };
    assert!(r.recognise(&rgb, &f, &expect(30.0, 50.0)).is_none());
}

/// `frame` with seeded noise of deviation `sd` added.
fn noisy(mut f: Vec<u8>, sd: f64, mut state: u64) -> Vec<u8> {
    for p in &mut f {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let n = ((state & 0xff) as f64 + ((state >> 8) & 0xff) as f64) / 255.0 - 1.0; // sd 0.41
        *p = (f64::from(*p) + n * sd / 0.41).round().clamp(0.0, 255.0) as u8;
    }
    f
}

/// The bearing of the boundary at column `u` of the test frames.
fn bearing(u: f64) -> f64 {
    ((32.0 - u) / 55.4f64).atan()
}

#[test]
fn a_dim_noisy_edge_is_found_where_it_is() {
    // A 25-level step at column 40 of a dim frame (grey 60 to 85) under noise of sd 8:
    // the old mean absolute difference had a noise floor of 9 levels everywhere.
    let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
    let f = noisy(frame(&[(0, 60), (40, 85)]), 8.0, 0x2545_f491_4f6c_dd1d);
    let mut r = LineLandmarks::new(55.4, 12.0);
    let s = r.recognise(&h, &f, &expect(30.0, 50.0)).expect("an answer");
    assert_eq!(s.kind, SightingKind::Bearing as u32, "found, not ambiguous");
    assert!((s.a - bearing(40.0)).abs() < 0.25 / 55.4, "within a quarter pixel: {}", s.a);
}

#[test]
fn a_soft_noisy_edge_counts_whole() {
    // The harsh condition's end-wall corner: a 36-level step spread over three columns by
    // the lens (12 a column), noise of sd 8. Column by column, no step stands out of the
    // noise's mean absolute difference (9 levels); across three columns it is whole.
    let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
    for seed in [1u64, 2, 3, 4, 5] {
        let f = noisy(frame(&[(0, 100), (39, 112), (40, 124), (41, 136)]), 8.0, 0x9e37_79b9 * seed);
        let mut r = LineLandmarks::new(55.4, 12.0).with_blur(1);
        let s = r.recognise(&h, &f, &expect(25.0, 55.0)).expect("an answer");
        assert_eq!(s.kind, SightingKind::Bearing as u32, "seed {seed}");
        // The ramp's middle step is the boundary at 40.
        assert!((s.a - bearing(40.0)).abs() < 0.5 / 55.4, "seed {seed}: within half a pixel: {}", s.a);
    }
}

#[test]
fn noise_alone_is_not_an_edge_however_low_the_threshold() {
    let h = FrameHeader::new(1, 0, 64, 48, Encoding::Mono8);
    for seed in [1u64, 2, 3, 4, 5, 6, 7, 8] {
        let f = noisy(frame(&[(0, 120)]), 8.0, 0x51_7cc1_b727 * seed);
        let mut r = LineLandmarks::new(55.4, 0.5);
        let s = r.recognise(&h, &f, &expect(5.0, 60.0)).expect("an answer");
        assert_eq!(s.kind, SightingKind::NotFound as u32, "seed {seed}");
    }
}
