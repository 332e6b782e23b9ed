//! The small valid recording the mutation harness damages, written with the crate's own
//! [`Recorder`] (no services run): a few hundred messages of six topics (the four replay inputs,
//! a camera frame among them, odometry and the mission status) in five chunks, the world with its
//! `harvey.world` seed, a launch file and one data file as attachments.

use std::path::Path;

use harvey_geometry::Rng;
use harvey_msgs::{
    EncodersRaw, Encoding, FrameHeader, Header, MissionStatus, Odometry, Pose2, SonarRaw, TruePose, topics,
};
use harvey_recording::Recorder;

/// The world the sample carries (its `[poles]` placed by seed 5).
pub const ARENA: &str = include_str!("../../../../worlds/arena.toml");
/// The launch file it carries, which names one data file.
pub const LAUNCH: &str = "[launch]\nname = \"sample\"\nfiles = [\"fsa/table.toml\"]\n";

/// Ticks of 50 ms; a frame every other tick, a chunk flushed every 16.
const TICKS: u64 = 64;

/// Writes the sample to `path`; the same bytes every time.
pub fn write(path: &Path) {
    let mut rng = Rng::new(20);
    let mut r = Recorder::create(path).expect("create");
    r.attach_world("arena.toml", ARENA, 5).expect("world");
    r.attach_launch("sample.toml", LAUNCH).expect("launch");
    r.attach_data("fsa/table.toml", b"[[state]]\nname = \"q0\"\n").expect("data");
    let truth = r.channel::<TruePose>(topics::SIM_TRUTH.name).expect("channel");
    let sonar = r.channel::<SonarRaw>(topics::DRV_SONAR_RAW.name).expect("channel");
    let encoders = r.channel::<EncodersRaw>(topics::DRV_ENCODERS_RAW.name).expect("channel");
    let frames = r.image_channel(topics::CAMERA_FRAME.name).expect("channel");
    let odometry = r.channel::<Odometry>(topics::ODOMETRY.name).expect("channel");
    let status = r.channel::<MissionStatus>(topics::EXECUTIVE_STATUS.name).expect("channel");
    for tick in 1..=TICKS {
        let header = Header::new(tick, tick * 50_000_000);
        let pose = Pose2 { x_m: rng.uniform(), y_m: rng.uniform(), heading_rad: rng.normal(0.0, 1.0) };
        r.record(truth, &TruePose { header, world_from_robot: pose }).expect("truth");
        let range_m = std::array::from_fn(|_| rng.uniform() as f32 * 3.0);
        let ring = SonarRaw { header, bank: (tick % 3) as u32, echo_mask: 0b1011_0110, range_m };
        r.record(sonar, &ring).expect("sonar");
        let e = EncodersRaw {
            header,
            x_m: pose.x_m,
            y_m: pose.y_m,
            heading_rad: pose.heading_rad,
            ..Default::default()
        };
        r.record(encoders, &e).expect("encoders");
        if tick % 2 == 0 {
            let pixels: Vec<u8> = (0..16 * 12).map(|_| (rng.next_u64() & 0x3f) as u8).collect();
            let h = FrameHeader::new(tick / 2, header.stamp_ns, 16, 12, Encoding::Mono8);
            r.record_frame(frames, &h, &pixels).expect("frame");
        }
        r.record(
            odometry,
            &Odometry { header, world_from_robot: pose, travelled_m: tick as f64, ..Default::default() },
        )
        .expect("odometry");
        r.record(status, &MissionStatus { header, step: tick as u32, estimated: pose, ..Default::default() })
            .expect("status");
        if tick % 16 == 0 {
            r.flush().expect("flush");
        }
    }
    r.finish().expect("finish");
}
