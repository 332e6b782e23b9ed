//! Which instruction-set path the kernels run: chosen once per process from what the CPU has,
//! optionally lowered (never raised) by `HARVEY_SIMD=portable|neon|avx2|avx512` for measurement.
//!
//! Every hot kernel has one portable body the compiler can vectorise, compiled again for each
//! path with [`multiversion::target`], plus hand-written intrinsics where the compiler cannot
//! find the instructions by itself (the correlation cross-sum, Moravec's peak row pass). Each
//! kernel matches on a [`Path`]; tests run every [`Path::available`] one and compare bit for bit.
//! On aarch64, NEON is part of the baseline target, so the portable bodies are already NEON
//! code there; [`Path::Neon`] adds the hand-written NEON cross-sum (`cross.rs`).

use std::fmt;
use std::sync::OnceLock;

/// The environment variable that lowers the path for measurement.
pub const ENV: &str = "HARVEY_SIMD";

/// An instruction-set path, slowest first (on its own architecture: a path the CPU cannot run
/// is lowered to the fastest slower one it can, so `avx512` asked of an ARM CPU gives `neon`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Path {
    /// Plain Rust for the build's baseline target.
    Portable,
    /// aarch64 Advanced SIMD (every aarch64 CPU has it).
    Neon,
    /// x86-64-v3: AVX2, FMA, BMI2.
    Avx2,
    /// AVX-512 F, BW and VNNI (on top of AVX2).
    Avx512,
}

impl Path {
    /// Every path, slowest first.
    pub const ALL: [Path; 4] = [Path::Portable, Path::Neon, Path::Avx2, Path::Avx512];

    /// The name `HARVEY_SIMD` takes.
    pub fn name(self) -> &'static str {
        match self {
            Path::Portable => "portable",
            Path::Neon => "neon",
            Path::Avx2 => "avx2",
            Path::Avx512 => "avx512",
        }
    }

    /// The path named `s` (as `HARVEY_SIMD` spells it).
    pub fn parse(s: &str) -> Option<Path> {
        Path::ALL.into_iter().find(|p| p.name() == s.trim().to_ascii_lowercase())
    }

    /// Whether this CPU can run the path.
    pub fn supported(self) -> bool {
        match self {
            Path::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Path::Avx2 => {
                std::is_x86_feature_detected!("avx2")
                    && std::is_x86_feature_detected!("fma")
                    && std::is_x86_feature_detected!("bmi2")
            }
            #[cfg(target_arch = "x86_64")]
            Path::Avx512 => {
                Path::Avx2.supported()
                    && std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512bw")
                    && std::is_x86_feature_detected!("avx512vnni")
            }
            #[cfg(target_arch = "aarch64")]
            Path::Neon => std::arch::is_aarch64_feature_detected!("neon"),
            #[allow(unreachable_patterns, reason = "which arms are left depends on the architecture")]
            _ => false,
        }
    }

    /// The fastest path this CPU has.
    pub fn best() -> Path {
        Path::ALL.into_iter().rev().find(|p| p.supported()).unwrap_or(Path::Portable)
    }

    /// Every path this CPU can run, slowest first (what the tests compare).
    pub fn available() -> Vec<Path> {
        Path::ALL.into_iter().filter(|p| p.supported()).collect()
    }

    /// The path the kernels use: the fastest the CPU has, or `HARVEY_SIMD` if that names a
    /// slower one (a faster one than the CPU has, or an unknown name, is ignored). Read once.
    pub fn active() -> Path {
        static ACTIVE: OnceLock<Path> = OnceLock::new();
        *ACTIVE.get_or_init(|| {
            let wanted = std::env::var(ENV).ok().and_then(|v| Path::parse(&v));
            Path::clamp(wanted.unwrap_or(Path::Avx512))
        })
    }

    /// `wanted` if the CPU has it, or else the fastest slower path it has.
    pub fn clamp(wanted: Path) -> Path {
        Path::ALL.into_iter().rev().filter(|p| *p <= wanted).find(|p| p.supported()).unwrap_or(Path::Portable)
    }
}

impl fmt::Display for Path {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The CPU's model name (from `/proc/cpuinfo`, where there is one; for benchmarks).
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| t.lines().find(|l| l.starts_with("model name")).map(|l| l.to_owned()))
        .and_then(|l| l.split_once(':').map(|(_, m)| m.trim().to_owned()))
        .unwrap_or_else(|| "unknown".to_owned())
}

/// The SIMD features of this CPU that the paths care about, space-separated (for benchmarks).
pub fn cpu_features() -> String {
    let mut out: Vec<&str> = Vec::new();
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! probe {
            ($($f:tt),*) => {$(
                if std::is_x86_feature_detected!($f) {
                    out.push($f);
                }
            )*};
        }
        probe!("sse4.2", "avx", "avx2", "fma", "bmi2", "avx512f", "avx512bw", "avx512vl", "avx512vnni");
    }
    #[cfg(target_arch = "aarch64")]
    {
        if std::arch::is_aarch64_feature_detected!("neon") {
            out.push("neon");
        }
    }
    out.join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_the_active_path_is_one_the_cpu_has() {
        for p in Path::ALL {
            assert_eq!(Path::parse(p.name()), Some(p));
        }
        assert_eq!(Path::parse("AVX2"), Some(Path::Avx2));
        assert_eq!(Path::parse("neon"), Some(Path::Neon));
        assert_eq!(Path::parse("sse2"), None);
        assert!(Path::active().supported());
        assert!(Path::clamp(Path::Avx512).supported());
        assert_eq!(Path::clamp(Path::Portable), Path::Portable);
        assert_eq!(Path::available().first(), Some(&Path::Portable));
        // A path of the other architecture is never chosen.
        assert!(Path::clamp(Path::Neon).supported());
        #[cfg(target_arch = "x86_64")]
        assert_eq!(Path::clamp(Path::Neon), Path::Portable);
        #[cfg(target_arch = "aarch64")]
        assert_eq!(Path::clamp(Path::Avx512), Path::Neon);
    }
}
