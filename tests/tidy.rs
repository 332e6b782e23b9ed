//! The conventions the build enforces: every Rust file opens with a `//!` line saying what it
//! is; only `crates/bus` uses iceoryx2 (the zero-copy marker aside); only the recording crate
//! and the recorder draw with rerun; only the Foxglove bridge serves with foxglove, only the Zenoh
//! bridge speaks zenoh; no service
//! crate depends on another service crate and no `crates/*` on a `services/*`, read from
//! `cargo metadata`. Each rule is a function over plain data, tested on a deliberate violation
//! as well as on the workspace itself.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use std::path::{Path, PathBuf};

/// One workspace package as the rules see it: its folder relative to the workspace root, and
/// its dependencies (name, folder relative to the root if a path dependency, kind).
#[derive(Debug, Clone)]
struct Package {
    name: String,
    dir: String,
    deps: Vec<Dep>,
}

#[derive(Debug, Clone)]
struct Dep {
    name: String,
    dir: Option<String>,
    dev: bool,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The workspace's packages, from `cargo metadata --no-deps`.
fn workspace() -> Vec<Package> {
    let out = std::process::Command::new(env!("CARGO"))
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .current_dir(root())
        .output()
        .expect("cargo metadata runs");
    assert!(out.status.success(), "cargo metadata: {}", String::from_utf8_lossy(&out.stderr));
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).expect("metadata is JSON");
    let base = root().canonicalize().expect("root");
    let rel = |p: &str| -> String {
        let p = Path::new(p);
        let p = if p.file_name().is_some_and(|f| f == "Cargo.toml") { p.parent().unwrap_or(p) } else { p };
        p.strip_prefix(&base).map(|r| r.display().to_string()).unwrap_or_else(|_| p.display().to_string())
    };
    meta["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .map(|p| Package {
            name: p["name"].as_str().expect("name").to_owned(),
            dir: rel(p["manifest_path"].as_str().expect("manifest")),
            deps: p["dependencies"]
                .as_array()
                .expect("dependencies")
                .iter()
                .map(|d| Dep {
                    name: d["name"].as_str().expect("dep name").to_owned(),
                    dir: d["path"].as_str().map(rel),
                    dev: d["kind"].as_str() == Some("dev"),
                })
                .collect(),
        })
        .collect()
}

fn is_service(dir: &str) -> bool {
    dir.starts_with("services/")
}

/// Services the CLI hosts for in-process runs: the nodes (`src/cmd/inproc/registry.rs`), the
/// simulated DRV and the bridge on their in-memory line (`src/cmd/inproc/drv.rs`).
const HOSTED: [&str; 8] = [
    "harvey-sonar",
    "harvey-encoders",
    "harvey-camera",
    "harvey-vision-workers",
    "harvey-ums",
    "harvey-executive",
    "harvey-sim-drv",
    "harvey-denning-bridge",
];

/// The dependency rule: no `services/*` depends on another `services/*` (dev-dependencies
/// included), no `crates/*` on any `services/*`, and the CLI (the root package) uses a service
/// as a library only to host its node in process (its integration tests may: they run
/// services' libraries together).
fn dependency_violations(packages: &[Package]) -> Vec<String> {
    let mut out = Vec::new();
    for p in packages {
        for d in &p.deps {
            let Some(dir) = d.dir.as_deref().filter(|d| is_service(d)) else { continue };
            let kind = if d.dev { "dev-dependency" } else { "dependency" };
            if is_service(&p.dir) && dir != p.dir {
                out.push(format!(
                    "service {} ({}) has a {kind} on service {} ({dir})",
                    p.name, p.dir, d.name
                ));
            } else if p.dir.starts_with("crates/") {
                out.push(format!("crate {} ({}) has a {kind} on service {} ({dir})", p.name, p.dir, d.name));
            } else if p.dir.is_empty() && !d.dev && !HOSTED.contains(&d.name.as_str()) {
                out.push(format!("the CLI ({}) uses service {} ({dir}) as a library", p.name, d.name));
            }
        }
    }
    out
}

/// Which packages may name a dependency: iceoryx2 only in the bus (its marker trait and derive
/// also in the wire types and the pose they carry), rerun only where runs are drawn, foxglove
/// (a WebSocket server) only in the Foxglove bridge, zenoh only in the Zenoh bridge.
fn confinement_violations(packages: &[Package]) -> Vec<String> {
    let allowed = |dep: &str| -> Option<&'static [&'static str]> {
        match dep {
            "iceoryx2" | "iceoryx2-bb-posix" => Some(&["crates/bus"]),
            "iceoryx2-bb-elementary-traits" | "iceoryx2-bb-derive-macros" => {
                Some(&["crates/bus", "crates/msgs", "crates/geometry"])
            }
            "rerun" => Some(&["crates/recording", "services/recorder"]),
            "foxglove" => Some(&["services/foxglove-bridge"]),
            "zenoh" => Some(&["services/zenoh-bridge"]),
            _ => None,
        }
    };
    let mut out = Vec::new();
    for p in packages {
        for d in &p.deps {
            if let Some(ok) = allowed(&d.name).filter(|ok| !ok.contains(&p.dir.as_str())) {
                out.push(format!(
                    "{} ({}) depends on {}, which only {} may",
                    p.name,
                    p.dir,
                    d.name,
                    ok.join(", ")
                ));
            }
        }
    }
    out
}

/// Every `.rs` file under `dir` (build outputs and hidden folders skipped).
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let path = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') || name == "target" {
            continue;
        }
        if path.is_dir() {
            rust_files(&path, out);
        } else if name.ends_with(".rs") {
            out.push(path);
        }
    }
}

/// A file's text breaks the header rule when its first line is not a `//!` comment.
fn header_violation(file: &str, text: &str) -> Option<String> {
    let first = text.lines().next().unwrap_or("");
    (!first.starts_with("//!"))
        .then(|| format!("{file}: the first line is not a `//!` line saying what the file is"))
}

/// Source that names iceoryx2 outside the bus (comments aside).
fn iceoryx2_in_source(file: &str, text: &str) -> Option<String> {
    // The needle is built so that this file does not match itself.
    let needle = ["iceoryx2", "::"].concat();
    let code = text.lines().filter(|l| !l.trim_start().starts_with("//")).any(|l| l.contains(&needle));
    code.then(|| format!("{file}: uses iceoryx2 directly (only crates/bus may)"))
}

fn tree_violations() -> Vec<String> {
    let mut files = Vec::new();
    for d in ["src", "crates", "services", "tests", "benches"] {
        rust_files(&root().join(d), &mut files);
    }
    assert!(files.len() > 100, "found only {} Rust files: is the walk wrong?", files.len());
    let mut out = Vec::new();
    for f in files {
        let rel = f.strip_prefix(root()).unwrap_or(&f).display().to_string();
        let text = std::fs::read_to_string(&f).unwrap_or_default();
        out.extend(header_violation(&rel, &text));
        if !rel.starts_with("crates/bus/") {
            out.extend(iceoryx2_in_source(&rel, &text));
        }
    }
    out
}

#[test]
fn the_workspace_keeps_its_conventions() {
    let packages = workspace();
    assert!(packages.iter().any(|p| p.dir == "services/executive"), "metadata lists the services");
    let mut v = dependency_violations(&packages);
    v.extend(confinement_violations(&packages));
    v.extend(tree_violations());
    assert!(v.is_empty(), "convention violations:\n{}", v.join("\n"));
}

#[test]
fn each_rule_catches_a_deliberate_violation() {
    let mut packages = workspace();
    let dep = |name: &str, dir: &str, dev: bool| Dep { name: name.into(), dir: Some(dir.into()), dev };
    let ums = packages.iter_mut().find(|p| p.dir == "services/ums").expect("ums");
    ums.deps.push(dep("harvey-sim-drv", "services/sim-drv", true));
    let vision = packages.iter_mut().find(|p| p.dir == "crates/vision").expect("vision");
    vision.deps.push(dep("harvey-camera", "services/camera", true));
    let cli = packages.iter_mut().find(|p| p.dir.is_empty()).expect("the CLI");
    cli.deps.push(dep("harvey-recorder", "services/recorder", false));
    cli.deps.push(Dep { name: "rerun".into(), dir: None, dev: false });
    cli.deps.push(Dep { name: "foxglove".into(), dir: None, dev: false });
    cli.deps.push(Dep { name: "zenoh".into(), dir: None, dev: false });
    let v = dependency_violations(&packages);
    assert_eq!(v.len(), 3, "{v:#?}");
    assert!(v.iter().any(|m| m.starts_with("service harvey-ums") && m.contains("harvey-sim-drv")), "{v:#?}");
    assert!(v.iter().any(|m| m.contains("crate harvey-vision") && m.contains("harvey-camera")), "{v:#?}");
    assert!(v.iter().any(|m| m.contains("the CLI") && m.contains("harvey-recorder")), "{v:#?}");
    let c = confinement_violations(&packages);
    assert!(
        c.len() == 3 && c[0].contains("rerun") && c[1].contains("foxglove") && c[2].contains("zenoh"),
        "{c:#?}"
    );
    assert!(header_violation("x.rs", "use std::fs;\n").is_some());
    assert!(header_violation("x.rs", "//! What x is.\nuse std::fs;\n").is_none());
    let direct = ["let n = iceoryx2", "::node::NodeBuilder::new();\n"].concat();
    assert!(iceoryx2_in_source("x.rs", &direct).is_some());
    assert!(iceoryx2_in_source("x.rs", &["// iceoryx2", "::node lists nodes\n"].concat()).is_none());
}
