//! The kernels on aarch64: cross-compiles this crate's unit tests and `simd_paths` for
//! `aarch64-unknown-linux-gnu` and runs them under `qemu-aarch64`, so the NEON path is checked
//! bit for bit against the portable one on an x86-64 machine. Needs the Rust target, a cross
//! linker and qemu-user (`scripts/test` installs them where it can, and then sets
//! `HARVEY_AARCH64_REQUIRED=1`, which turns a missing tool into a failure instead of a skip).
#![cfg(target_arch = "x86_64")]
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use std::path::{Path, PathBuf};
use std::process::Command;

const TARGET: &str = "aarch64-unknown-linux-gnu";
const LINKER: &str = "aarch64-linux-gnu-gcc";
const QEMU: &str = "qemu-aarch64";
/// Where Debian's cross toolchain keeps the aarch64 C library qemu needs.
const SYSROOT: &str = "/usr/aarch64-linux-gnu";

fn on_path(tool: &str) -> bool {
    Command::new(tool).arg("--version").output().is_ok_and(|o| o.status.success())
}

/// The Rust standard library for `TARGET` is installed.
fn target_installed() -> bool {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let Ok(out) = Command::new(rustc).args(["--print", "sysroot"]).output() else { return false };
    let sysroot = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    sysroot.join("lib/rustlib").join(TARGET).join("lib").is_dir()
}

#[test]
fn the_kernels_agree_on_every_path_under_qemu_aarch64() {
    let missing: Vec<&str> = [
        (!target_installed()).then_some("the Rust target aarch64-unknown-linux-gnu"),
        (!on_path(LINKER)).then_some(LINKER),
        (!on_path(QEMU)).then_some(QEMU),
        (!Path::new(SYSROOT).is_dir()).then_some(SYSROOT),
    ]
    .into_iter()
    .flatten()
    .collect();
    if !missing.is_empty() {
        let required = std::env::var("HARVEY_AARCH64_REQUIRED").is_ok_and(|v| v == "1");
        assert!(!required, "HARVEY_AARCH64_REQUIRED=1 but missing: {missing:?}");
        eprintln!("skipped: no aarch64 toolchain here (missing {missing:?})");
        return;
    }
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let target_dir = manifest.join("../../target/aarch64");
    let out = Command::new(env!("CARGO"))
        .current_dir(manifest)
        .args([
            "test",
            "--release",
            "-p",
            "harvey-vision",
            "--target",
            TARGET,
            "--lib",
            "--test",
            "simd_paths",
        ])
        .env("CARGO_TARGET_DIR", &target_dir)
        .env("CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER", LINKER)
        .env("CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER", format!("{QEMU} -L {SYSROOT}"))
        .env_remove("HARVEY_SIMD")
        .output()
        .expect("cargo runs");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "the aarch64 tests failed under qemu:\n{text}");
    // The NEON path was among those compared (simd_paths asserts it is available on aarch64).
    let passed: usize = text
        .lines()
        .filter_map(|l| l.strip_prefix("test result: ok. "))
        .filter_map(|l| l.split(' ').next()?.parse::<usize>().ok())
        .sum();
    assert!(passed >= 3, "the unit tests and simd_paths ran ({passed} passed):\n{text}");
    assert!(text.contains("neon_is_the_path_an_aarch64_cpu_takes ... ok"), "{text}");
}
