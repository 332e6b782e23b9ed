//! The bus within one process (two nodes): typed delivery with wake-ups, frames in place, a
//! clock party that runs a tick once however often it is reported, and clear errors for a topic
//! opened with the wrong type and for bad prefixes.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use std::time::Duration;

use harvey_bus::{Bus, BusError, Lockstep, Pace, Step, Waiter, Wake};
use harvey_msgs::{Encoding, FrameHeader, Header, Pose2, Qos, Topic, TruePose, UncertaintyMap, topics};

fn prefix(tag: &str) -> String {
    format!("tb{tag}{}_", std::process::id())
}

#[test]
fn messages_arrive_in_order_and_wake_the_waiter() {
    let p = prefix("a");
    {
        let a = Bus::join_with_prefix("a", &p).expect("join");
        let b = Bus::join_with_prefix("b", &p).expect("join");
        let sub = b.subscriber(topics::SIM_TRUTH).expect("sub");
        let publ = a.publisher(topics::SIM_TRUTH).expect("pub");
        let waiter = Waiter::new().expect("waiter");
        let _g = waiter.attach(&sub).expect("attach");
        assert_eq!(waiter.wait(Some(Duration::from_millis(50))).expect("wait"), Wake::Timeout);
        for i in 1..=3 {
            let m = TruePose {
                header: Header::new(i, i * 10),
                world_from_robot: Pose2 { x_m: i as f64, ..Default::default() },
            };
            assert_eq!(publ.send(&m).expect("send"), 1);
        }
        assert_eq!(waiter.wait(Some(Duration::from_secs(5))).expect("wait"), Wake::Ready);
        let mut got = Vec::new();
        assert_eq!(sub.drain_into(&mut got).expect("drain"), 3);
        assert_eq!(got.iter().map(|m| m.header.seq).collect::<Vec<_>>(), [1, 2, 3]);
        // Drained and its wake-ups consumed: the waiter sleeps again.
        assert_eq!(waiter.wait(Some(Duration::from_millis(50))).expect("wait"), Wake::Timeout);
    }
    harvey_bus::retire_domain(&p).expect("retire");
}

#[test]
fn a_tick_reported_again_by_a_restarted_predecessor_is_run_once() {
    let p = prefix("r");
    {
        let bus = Bus::join_with_prefix("r", &p).expect("join");
        let me = Pace::with(Some(Lockstep::new(&bus, "me", "pred").expect("party")));
        let waiter = Waiter::new().expect("waiter");
        let _a = me.attach(&waiter, &[]).expect("attach");
        let pred = Lockstep::new(&bus, "pred", "tail").expect("predecessor");
        pred.finish(50).expect("report");
        // The predecessor restarted from a checkpoint a tick behind: it reports 50 again.
        let restarted = Lockstep::new(&bus, "pred", "tail").expect("restarted");
        restarted.finish(50).expect("report");
        restarted.finish(100).expect("report");
        let mut turns = Vec::new();
        while let Step::Go(t) = me.next(&waiter, Some(Duration::from_millis(300))).expect("next") {
            turns.push(t);
            me.done().expect("done");
        }
        assert_eq!(turns, [Some(50), Some(100)]);
    }
    harvey_bus::retire_domain(&p).expect("retire");
}

#[test]
fn frames_are_loaned_written_and_read_in_place() {
    let p = prefix("f");
    {
        let bus = Bus::join_with_prefix("f", &p).expect("join");
        let sub = bus.frame_subscriber(topics::CAMERA_FRAME).expect("sub");
        let publ = bus.frame_publisher(topics::CAMERA_FRAME, 64 * 48).expect("pub");
        let mut loan = publ.loan(FrameHeader::new(1, 5, 64, 48, Encoding::Mono8)).expect("loan");
        loan.pixels_mut().iter_mut().enumerate().for_each(|(i, p)| *p = (i % 256) as u8);
        loan.send().expect("send");
        let frame = sub.take().expect("take").expect("a frame");
        assert_eq!(frame.header().seq, 1);
        assert!(frame.pixels().iter().enumerate().all(|(i, p)| *p == (i % 256) as u8));
        drop(frame);
        // Several queued: `latest` releases the older ones before it takes the next, so it
        // never holds more frames than the topic lets a subscriber borrow.
        for seq in 2..=4 {
            let mut loan = publ.loan(FrameHeader::new(seq, seq, 64, 48, Encoding::Mono8)).expect("loan");
            loan.pixels_mut().fill(seq as u8);
            loan.send().expect("send");
        }
        let newest = sub.latest().expect("no borrow overflow").expect("a frame");
        assert_eq!(newest.header().seq, 4);
        assert!(newest.pixels().iter().all(|p| *p == 4));
        drop(newest);
        assert!(sub.latest().expect("empty").is_none());
        let too_big = publ.loan(FrameHeader::new(2, 6, 65, 48, Encoding::Mono8));
        assert!(matches!(too_big, Err(BusError::Topic { what: "frame size out of range", .. })));
    }
    harvey_bus::retire_domain(&p).expect("retire");
}

#[test]
fn a_topic_opened_with_another_type_is_a_clear_error() {
    let p = prefix("t");
    {
        let bus = Bus::join_with_prefix("t", &p).expect("join");
        let _truth = bus.publisher(topics::SIM_TRUTH).expect("pub");
        let wrong: Topic<UncertaintyMap> = Topic::new("sim/truth", Qos::STATE);
        let err = bus.subscriber(wrong).err().expect("type mismatch must fail");
        assert!(
            matches!(err, BusError::IncompatibleTopic { ref topic, .. } if topic == "sim/truth"),
            "{err}"
        );
        assert!(err.to_string().contains("topic `sim/truth` exists with another payload type"), "{err}");
    }
    harvey_bus::retire_domain(&p).expect("retire");
}

#[test]
fn bad_prefixes_are_refused() {
    for bad in ["", "has space", "slash/no", "x".repeat(41).as_str()] {
        assert!(matches!(Bus::join_with_prefix("n", bad), Err(BusError::BadPrefix { .. })), "{bad:?}");
    }
}
