//! Rust's payload layouts and topic table as JSON, for `python -m harvey_client check-layout`,
//! and the test that the Python client's ctypes structures and topic table are Rust's.

use std::collections::BTreeSet;
use std::mem::{align_of, offset_of, size_of};
use std::path::PathBuf;

use harvey_msgs::{
    BehaviourState, Detections, EncodersRaw, Expectation, Feature, FrameHeader, Header, LandmarkSighting,
    LogLine, MissionStatus, MotionCommand, Odometry, PlanSketch, Pose2, PoseFix, Progress, Qos,
    ServoCorrection, SonarRaw, SonarRing, Topic, TruePose, UncertaintyMap, VisionItem, VisionRequest,
    VisionResult, ZeroCopySend, topics,
};
use serde_json::{Value, json};

use crate::common;
use crate::text;
use crate::venv::client;

fn field_size<T, F>(_: impl Fn(&T) -> &F) -> usize {
    size_of::<F>()
}

/// `{name, type_name, size, align, fields: [{name, offset, size}]}` of a payload type, its
/// fields listed in declaration order.
macro_rules! layout {
    ($t:ty { $($f:ident),* $(,)? }) => {
        json!({
            "name": stringify!($t),
            // SAFETY: reading the type's name has no precondition; the trait marks it unsafe
            // because implementing it promises a layout.
            "type_name": unsafe { <$t as ZeroCopySend>::type_name() },
            "size": size_of::<$t>(),
            "align": align_of::<$t>(),
            "fields": [$(json!({
                "name": stringify!($f),
                "offset": offset_of!($t, $f),
                "size": field_size(|v: &$t| &v.$f),
            })),*],
        })
    };
}

fn rust_layouts() -> Vec<Value> {
    vec![
        layout!(Header { seq, stamp_ns }),
        layout!(Pose2 { x_m, y_m, heading_rad }),
        layout!(TruePose { header, world_from_robot }),
        layout!(Progress { header }),
        layout!(SonarRaw { header, bank, echo_mask, range_m }),
        layout!(SonarRing { header, range_m, bearing_rad, reading_stamp_ns, valid_mask, panic_stop }),
        layout!(EncodersRaw { header, x_m, y_m, heading_rad, moving, command_id }),
        layout!(MotionCommand {
            header,
            kind,
            urgent,
            distance_m,
            angle_rad,
            linear_mps,
            angular_radps,
            command_id,
            reserved
        }),
        layout!(Odometry {
            header,
            world_from_robot,
            travelled_m,
            turned_rad,
            command,
            moving,
            command_accepted
        }),
        layout!(Feature { x_px, y_px, score, kind }),
        layout!(Detections { header, frame_seq, algorithm, count, confidence, reserved, features }),
        layout!(UncertaintyMap {
            header,
            centre,
            vertex_count,
            lost,
            vertices_m,
            heading_cw_rad,
            heading_ccw_rad,
            area_m2,
            missed_landmarks,
            reserved
        }),
        layout!(LandmarkSighting { header, frame_seq, landmark_index, kind, a, a_sd, b, b_sd }),
        layout!(Expectation { header, landmark_index, class, window_px, width_px, height_px, contrast }),
        layout!(MissionStatus {
            header,
            state,
            step,
            step_count,
            servo,
            estimated,
            goal,
            sonar_rings_seen,
            detections_seen,
            maps_seen
        }),
        layout!(ServoCorrection {
            header,
            increment,
            landmark_index,
            found_px,
            heading_error_rad,
            correction_rad,
            offset_m,
            shortfall_m
        }),
        layout!(PoseFix { header, expected, refined, asked, found, kept, reserved, rms_px }),
        layout!(PlanSketch {
            header,
            places_m,
            place_count,
            primitive_mask,
            stage,
            checks,
            replans,
            last_outcome,
            last_off_m
        }),
        layout!(BehaviourState {
            header,
            at,
            fsa_state,
            transitions,
            last_trigger,
            achieved,
            vectors_mps,
            linear_mps,
            angular_radps
        }),
        layout!(VisionRequest {
            header,
            request_id,
            algorithm,
            standing,
            landmark_index,
            expected,
            window_px,
            params
        }),
        layout!(VisionItem { values }),
        layout!(VisionResult {
            header,
            frame_seq,
            request_id,
            algorithm,
            status,
            found,
            count,
            reserved,
            items
        }),
        layout!(LogLine { header, level, name_len, text_len, name, text }),
        layout!(FrameHeader { seq, stamp_ns, width_px, height_px, stride_bytes, encoding, views, reserved }),
    ]
}

fn qos(q: Qos) -> Value {
    json!({
        "buffer": q.buffer,
        "borrowed": q.borrowed,
        "history": q.history,
        "max_publishers": q.max_publishers,
        "max_subscribers": q.max_subscribers,
    })
}

fn topic<T: ZeroCopySend>(t: Topic<T>) -> Value {
    // SAFETY: as in `layout!`.
    json!({ "name": t.name, "type_name": unsafe { <T as ZeroCopySend>::type_name() }, "frames": false, "qos": qos(t.qos) })
}

fn rust_topics() -> Vec<Value> {
    use topics::*;
    let frames = json!({
        "name": CAMERA_FRAME.name,
        // SAFETY: as in `layout!`.
        "type_name": unsafe { <FrameHeader as ZeroCopySend>::type_name() },
        "frames": true,
        "qos": qos(CAMERA_FRAME.qos),
    });
    vec![
        topic(SIM_TRUTH),
        topic(DRV_SONAR_RAW),
        topic(DRV_ENCODERS_RAW),
        topic(VEHICLE_COMMAND),
        topic(VEHICLE_REFLEX),
        topic(SONAR_RING),
        topic(ODOMETRY),
        topic(VISION_DETECTIONS),
        topic(UMS_MAP),
        topic(VISION_SIGHTINGS),
        topic(UMS_EXPECTATIONS),
        topic(EXECUTIVE_STATUS),
        topic(EXECUTIVE_SERVO),
        topic(EXECUTIVE_POSE),
        topic(EXECUTIVE_PLAN),
        topic(EXECUTIVE_BEHAVIOUR),
        topic(VISION_REQUESTS),
        topic(VISION_RESULTS),
        topic(ROSOUT),
        frames,
    ]
}

/// The `#[type_name("harvey_msgs/...")]` attributes in the source of the message types.
fn declared_type_names() -> BTreeSet<String> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(common::repo().join("crates/msgs/src"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.push(common::repo().join("crates/geometry/src/pose.rs"));
    let mut names = BTreeSet::new();
    for f in files {
        let src = std::fs::read_to_string(&f).unwrap();
        for piece in src.split("#[type_name(\"").skip(1) {
            names.insert(piece.split('"').next().unwrap().to_owned());
        }
    }
    names
}

#[test]
fn the_python_types_and_topic_table_are_rusts() {
    let types = rust_layouts();
    let topics = rust_topics();
    // Every payload declared in the source is in the list above, and every topic.
    let listed: BTreeSet<String> =
        types.iter().map(|t| t["type_name"].as_str().unwrap().to_owned()).collect();
    assert_eq!(listed, declared_type_names(), "a payload type is missing from this test's list");
    let names: Vec<&str> = topics.iter().map(|t| t["name"].as_str().unwrap()).collect();
    assert_eq!(names, topics::ALL, "the topic list here is not `topics::ALL`");

    let dir = common::scratch("pylayout");
    let file = dir.join("rust-layouts.json");
    std::fs::write(&file, serde_json::to_vec_pretty(&json!({ "types": types, "topics": topics })).unwrap())
        .unwrap();
    let out = client(&["check-layout", file.to_str().unwrap()]).output().unwrap();
    let fields: usize = types.iter().map(|t| t["fields"].as_array().unwrap().len()).sum();
    println!("{}", text(&out).trim());
    assert!(out.status.success(), "{}", text(&out));
    let summary = format!(
        "layout: {} types, {fields} fields, {} topics compared, 0 mismatches",
        types.len(),
        topics.len()
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains(&summary), "{}", text(&out));
    assert_eq!((types.len(), topics.len()), (24, 20));

    // The comparison is not vacuous: one offset, one QoS number and one type name changed are
    // each reported.
    let mut wrong = json!({ "types": types, "topics": topics });
    let ring = wrong["types"].as_array_mut().unwrap().iter_mut().find(|t| t["name"] == "SonarRing").unwrap();
    ring["fields"][5]["offset"] = json!(408);
    wrong["topics"][6]["qos"]["buffer"] = json!(8);
    wrong["types"][0]["type_name"] = json!("harvey_msgs/Hdr");
    std::fs::write(&file, serde_json::to_vec(&wrong).unwrap()).unwrap();
    let out = client(&["check-layout", file.to_str().unwrap()]).output().unwrap();
    let said = text(&out);
    assert!(!out.status.success(), "{said}");
    assert!(said.contains("3 mismatches"), "{said}");
    assert!(
        said.contains("SonarRing fields")
            && said.contains("topic odometry")
            && said.contains("Header.type_name")
    );
    std::fs::remove_dir_all(&dir).ok();
}
