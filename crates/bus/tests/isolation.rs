//! Domains stay apart on disk: retiring one removes exactly its own shared-memory files (not
//! those of a domain whose prefix starts with its own), and every file a domain creates is
//! private to its user (0600).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use std::os::unix::fs::PermissionsExt;

use harvey_bus::{Bus, Waiter, domain_files};
use harvey_msgs::topics;

/// Joins `prefix` with a publisher, a subscriber and a frame topic: every kind of file.
fn populate(prefix: &str) -> (Bus, impl Sized) {
    let bus = Bus::join_with_prefix("iso", prefix).expect("join");
    let ports = (
        bus.publisher(topics::SIM_TRUTH).expect("pub"),
        bus.subscriber(topics::SIM_TRUTH).expect("sub"),
        bus.frame_publisher(topics::CAMERA_FRAME, 64).expect("frames"),
        Waiter::new().expect("waiter"),
    );
    (bus, ports)
}

#[test]
fn retiring_a_domain_leaves_one_whose_prefix_extends_it() {
    let a = format!("iso_a{}", std::process::id());
    let a2 = format!("{a}2_");
    {
        let _a = populate(&a);
        let _a2 = populate(&a2);
        assert!(!domain_files(&a).is_empty() && !domain_files(&a2).is_empty());
        assert!(domain_files(&a).iter().all(|f| !domain_files(&a2).contains(f)), "the two lists are apart");
    }
    let before = domain_files(&a2);
    assert!(harvey_bus::retire_domain(&a).expect("retire a") > 0);
    assert_eq!(domain_files(&a), Vec::<std::path::PathBuf>::new());
    assert_eq!(domain_files(&a2), before, "the other domain's files stay");
    assert!(harvey_bus::retire_domain(&a2).expect("retire a2") > 0);
    assert!(domain_files(&a2).is_empty());
}

#[test]
fn every_shared_memory_file_is_private() {
    let p = format!("iso_m{}_", std::process::id());
    {
        let _d = populate(&p);
        // A second member opens what the first created: the files stay usable and private.
        let other = Bus::join_with_prefix("iso2", &p).expect("join");
        let _sub = other.subscriber(topics::SIM_TRUTH).expect("sub");
        let files = domain_files(&p);
        assert!(files.iter().any(|f| f.to_string_lossy().ends_with(".global_mgmt")), "{files:?}");
        for f in &files {
            let mode = std::fs::metadata(f).expect("stat").permissions().mode() & 0o777;
            assert_eq!(mode, 0o600, "{} is {mode:o}", f.display());
        }
    }
    harvey_bus::retire_domain(&p).expect("retire");
}
