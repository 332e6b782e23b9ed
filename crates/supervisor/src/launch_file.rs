//! Launch files: which services to start, in what order, with which arguments and restart
//! policy. Loading checks them; errors name the file, line and key.

use std::path::{Path, PathBuf};

use harvey_recording::data_files::is_plain_relative;
use serde::Deserialize;

use crate::bounds::{MAX_SERVICES, Refused, check_service, check_settings, offset_of};
use crate::config::{ClockMode, Service, Settings};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    launch: Settings,
    #[serde(rename = "service", default)]
    services: Vec<Service>,
    /// The executive's; not the supervisor's business.
    #[allow(dead_code)]
    mission: Option<toml::Value>,
    /// Moving things for the simulator and the camera (`--movers ${mission}`).
    #[allow(dead_code)]
    mover: Option<toml::Value>,
}

/// A checked launch file.
#[derive(Debug, Clone)]
pub struct LaunchFile {
    pub path: PathBuf,
    pub settings: Settings,
    pub services: Vec<Service>,
}

/// A launch file that cannot be used, with where and why.
#[derive(Debug, thiserror::Error)]
#[error("{file}{}: {detail}", line.map(|l| format!(":{l}")).unwrap_or_default())]
pub struct LaunchError {
    pub file: String,
    pub line: Option<usize>,
    pub detail: String,
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

impl LaunchFile {
    pub fn load(path: &Path) -> Result<Self, LaunchError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| LaunchError {
            file: file.clone(),
            line: None,
            detail: format!("cannot read: {e}"),
        })?;
        let launch = Self::parse(&text, path)?;
        if let Some((missing, line)) = launch.data_files(&text).into_iter().find(|(f, _)| !f.is_file()) {
            return Err(LaunchError {
                file,
                line: Some(line),
                detail: format!("key `launch.files`: no file {}", missing.display()),
            });
        }
        Ok(launch)
    }

    pub fn parse(text: &str, path: &Path) -> Result<Self, LaunchError> {
        let file = path.display().to_string();
        let at = |offset: usize, detail: String| LaunchError {
            file: file.clone(),
            line: Some(line_of(text, offset)),
            detail,
        };
        let parsed: File = serde_path_to_error::deserialize(toml::Deserializer::new(text)).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            let line = inner.span().map(|s| line_of(text, s.start));
            LaunchError { file: file.clone(), line, detail: format!("key `{key}`: {}", inner.message()) }
        })?;
        if parsed.services.is_empty() {
            return Err(LaunchError { file, line: None, detail: "no [[service]] to launch".into() });
        }
        if parsed.services.len() > MAX_SERVICES {
            let n = parsed.services.len();
            return Err(at(
                parsed.services[MAX_SERVICES].name.span().start,
                format!("key `service[{MAX_SERVICES}]`: {n} services, more than the {MAX_SERVICES} allowed"),
            ));
        }
        for (i, s) in parsed.services.iter().enumerate() {
            let name = s.name();
            if !harvey_bus::is_plain_name(name) {
                return Err(at(
                    s.name.span().start,
                    format!("key `service[{i}].name`: `{name}` is not a plain name"),
                ));
            }
            if let Some(first) = parsed.services[..i].iter().find(|p| p.name() == name) {
                let first_line = line_of(text, first.name.span().start);
                return Err(at(
                    s.name.span().start,
                    format!(
                        "key `service[{i}].name`: service `{name}` is already named on line {first_line}"
                    ),
                ));
            }
        }
        let refused = |r: Refused| LaunchError {
            file: file.clone(),
            line: Some(line_of(text, offset_of(text, &r))),
            detail: format!("key `{}`: {}", r.path(), r.detail),
        };
        check_settings(&parsed.launch).map_err(refused)?;
        for (i, s) in parsed.services.iter().enumerate() {
            check_service(i, s).map_err(refused)?;
        }
        let Some(end) = &parsed.launch.end_with else {
            return Err(LaunchError {
                file,
                line: None,
                detail: "key `launch.end_with`: missing: name the service whose exit ends the launch".into(),
            });
        };
        if !parsed.services.iter().any(|s| s.name() == end.get_ref()) {
            return Err(at(
                end.span().start,
                format!("key `launch.end_with`: no service is named `{}`", end.get_ref()),
            ));
        }
        if parsed.launch.clock == ClockMode::Lockstep {
            let Some(master) = &parsed.launch.clock_master else {
                return Err(LaunchError {
                    file,
                    line: None,
                    detail: "key `launch.clock`: lockstep needs `launch.clock_master`".into(),
                });
            };
            if !parsed.services.iter().any(|s| s.clock_party && s.name() == master.get_ref()) {
                return Err(at(
                    master.span().start,
                    format!(
                        "key `launch.clock_master`: no service that is a clock party is named `{}`",
                        master.get_ref()
                    ),
                ));
            }
        }
        for (i, s) in parsed.services.iter().enumerate() {
            let Some(host) = &s.host else { continue };
            let h = host.get_ref();
            if !harvey_bus::is_plain_name(h) {
                return Err(at(
                    host.span().start,
                    format!(
                        "key `service[{i}].host`: `{h}`: a host's name takes letters, digits, `-` and `_`"
                    ),
                ));
            }
        }
        for f in &parsed.launch.files {
            if !is_plain_relative(f.get_ref()) {
                return Err(at(
                    f.span().start,
                    format!(
                        "key `launch.files`: `{}` is not a relative path inside the launch's folder",
                        f.get_ref()
                    ),
                ));
            }
        }
        Ok(Self { path: path.to_owned(), settings: parsed.launch, services: parsed.services })
    }

    /// The `[launch] files`, resolved against the launch file's folder, with the line naming each.
    pub fn data_files(&self, text: &str) -> Vec<(PathBuf, usize)> {
        let base = self.path.parent().unwrap_or(Path::new("."));
        self.settings.files.iter().map(|f| (base.join(f.get_ref()), line_of(text, f.span().start))).collect()
    }

    /// Deterministic mode: the clock parties in turn order, from the master round to the tail.
    pub fn clock_chain(&self) -> Vec<String> {
        let (ClockMode::Lockstep, Some(master)) = (self.settings.clock, &self.settings.clock_master) else {
            return Vec::new();
        };
        let mut chain: Vec<String> =
            self.services.iter().filter(|s| s.clock_party).map(|s| s.name().to_owned()).collect();
        let at = chain.iter().position(|n| n == master.get_ref()).unwrap_or(0);
        chain.rotate_left(at);
        chain
    }

    /// The world file, resolved against the launch file's folder.
    pub fn world_path(&self) -> Option<PathBuf> {
        let base = self.path.parent().unwrap_or(Path::new("."));
        self.settings.world.as_ref().map(|w| base.join(w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Restart;

    const OK: &str = "[launch]\nname = \"t\"\nend_with = \"b\"\n\n[[service]]\nname = \"a\"\nargs = [\"--x\", \"${seed}\"]\n\n[[service]]\nname = \"b\"\nrestart = \"never\"\n";

    fn parse(text: &str) -> Result<LaunchFile, LaunchError> {
        LaunchFile::parse(text, Path::new("m.toml"))
    }

    #[test]
    fn a_good_file_parses_with_defaults() {
        let l = parse(OK).expect("parses");
        assert_eq!(l.services.len(), 2);
        assert_eq!((l.services[0].restart, l.services[1].restart), (Restart::OnFailure, Restart::Never));
        assert_eq!(l.services[0].binary_name(), "harvey-a");
        assert_eq!(l.settings.seed, 1);
    }

    #[test]
    fn the_clock_chain_starts_at_the_master_and_skips_non_parties() {
        let text = "[launch]\nname = \"t\"\nclock = \"lockstep\"\nclock_master = \"c\"\nend_with = \"a\"\n\n[[service]]\nname = \"a\"\n\n[[service]]\nname = \"b\"\nclock_party = false\n\n[[service]]\nname = \"c\"\n\n[[service]]\nname = \"d\"\n";
        let l = parse(text).expect("parses");
        assert_eq!(l.clock_chain(), ["c", "d", "a"]);
        let e =
            parse(&text.replace("clock_master = \"c\"", "clock_master = \"b\"")).expect_err("not a party");
        assert!(e.to_string().starts_with("m.toml:4: key `launch.clock_master`"), "{e}");
        let e = parse(&text.replace("clock_master = \"c\"\n", "")).expect_err("no master");
        assert!(e.to_string().contains("lockstep needs `launch.clock_master`"), "{e}");
        assert!(parse(OK).expect("parses").clock_chain().is_empty(), "real time has no chain");
    }

    #[test]
    fn errors_name_file_line_and_key() {
        let bad = OK.replace("restart = \"never\"", "restart = \"sometimes\"");
        let e = parse(&bad).expect_err("bad policy").to_string();
        assert!(e.starts_with("m.toml:11: key `service[1].restart`"), "{e}");
        let dup = OK.replace("name = \"b\"", "name = \"a\"").replace("end_with = \"b\"", "end_with = \"a\"");
        let e = parse(&dup).expect_err("duplicate").to_string();
        assert!(
            e.starts_with("m.toml:10: key `service[1].name`: service `a` is already named on line 6"),
            "{e}"
        );
        let e = parse(&OK.replace("end_with = \"b\"", "end_with = \"zz\"")).expect_err("unknown").to_string();
        assert!(e.starts_with("m.toml:3: key `launch.end_with`"), "{e}");
        let e = parse(&OK.replace("args", "argz")).expect_err("unknown key").to_string();
        assert!(e.contains(":7: key `service[0].argz`") || e.contains(":7: key `service[0]`"), "{e}");
        let up = OK.replace("end_with", "files = [\"fsa/a.toml\",\n  \"../b.toml\"]\nend_with");
        let e = parse(&up).expect_err("outside the folder").to_string();
        assert!(e.starts_with("m.toml:4: key `launch.files`: `../b.toml` is not a relative path"), "{e}");
    }

    #[test]
    fn data_files_resolve_beside_the_launch_file_and_must_exist() {
        let dir = std::env::temp_dir().join(format!("harvey-files-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("fsa")).expect("tmp");
        let text = OK.replace("end_with", "files = [\"fsa/a.toml\"]\nend_with");
        std::fs::write(dir.join("m.toml"), &text).expect("write");
        let e = LaunchFile::load(&dir.join("m.toml")).expect_err("missing").to_string();
        assert!(e.contains("m.toml:3: key `launch.files`: no file") && e.contains("fsa/a.toml"), "{e}");
        std::fs::write(dir.join("fsa/a.toml"), "x").expect("write");
        let l = LaunchFile::load(&dir.join("m.toml")).expect("loads");
        assert_eq!(l.data_files(&text), [(dir.join("fsa/a.toml"), 3)]);
        std::fs::remove_dir_all(&dir).ok();
    }
}
