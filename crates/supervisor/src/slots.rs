//! A launch's services made ready to run, before anything starts: each one's executable found,
//! its arguments substituted, its bus environment set and its restart policy fresh.

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::child::{self, Running};
use crate::config::{LaunchFile, Service};
use crate::error::SupervisorError;
use crate::keeper_line::KeeperLine;
use crate::link::SpawnSpec;
use crate::outcome::Options;
use crate::policy::RestartPolicy;

/// One service of a launch: how to start it, and its process while it runs.
pub struct Slot {
    pub spec: Service,
    binary: PathBuf,
    args: Vec<String>,
    /// The bus domain, and the service's place in the clock chain.
    env: Vec<(&'static str, String)>,
    pub running: Option<Running>,
    pub policy: RestartPolicy,
}

impl Slot {
    pub fn name(&self) -> &str {
        self.spec.name()
    }

    /// Has the keeper start the service; returns once it is ready.
    pub fn spawn(&self, line: &mut KeeperLine, ready: Duration) -> Result<Running, SupervisorError> {
        let spec = SpawnSpec {
            name: self.name().to_owned(),
            binary: self.binary.clone(),
            args: self.args.clone(),
            env: self.env.iter().map(|(k, v)| ((*k).to_owned(), v.clone())).collect(),
        };
        child::spawn(line, spec, ready)
    }
}

/// The run folder's folder of the services' checkpoints (`harvey_runtime::checkpoint`).
pub const STATE_DIR: &str = "state";

/// Finds a service's executable: a path as given, else beside this program, else on `PATH`.
pub fn find_binary(name: &str) -> Option<PathBuf> {
    if name.contains('/') {
        let p = PathBuf::from(name);
        return p.is_file().then_some(p);
    }
    let beside = std::env::current_exe().ok().and_then(|e| e.parent().map(|d| d.join(name)));
    let on_path = std::env::var_os("PATH")
        .into_iter()
        .flat_map(|p| std::env::split_paths(&p).collect::<Vec<_>>())
        .map(|d| d.join(name));
    beside.into_iter().chain(on_path).find(|p| p.is_file())
}

/// The values a launch file's `${...}` stand for: the run folder, seed, launch file and its
/// folder (where the data files it names are), bus prefix and world (which must exist).
pub fn variables(
    launch: &LaunchFile,
    run_dir: &Path,
    prefix: &str,
) -> Result<Vec<(&'static str, String)>, SupervisorError> {
    let mut vars = vec![
        ("run_dir", absolute(run_dir).display().to_string()),
        ("seed", launch.settings.seed.to_string()),
        ("mission", absolute(&launch.path).display().to_string()),
        (
            "mission_dir",
            absolute(&launch.path).parent().map_or_else(String::new, |d| d.display().to_string()),
        ),
        ("prefix", prefix.to_owned()),
    ];
    if let Some(w) = launch.world_path() {
        if !w.is_file() {
            return Err(SupervisorError::NoWorld { launch: launch.path.clone(), world: w });
        }
        vars.push(("world", absolute(&w).display().to_string()));
    }
    Ok(vars)
}

/// A service's arguments with the launch's `${...}` substituted.
pub fn expand_args(service: &Service, vars: &[(&str, String)]) -> Vec<String> {
    service.args.iter().map(|a| substitute(a, vars)).collect()
}

fn substitute(arg: &str, vars: &[(&str, String)]) -> String {
    vars.iter().fold(arg.to_owned(), |a, (k, v)| a.replace(&format!("${{{k}}}"), v))
}

fn absolute(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_owned())
}

/// Creates the run folder and prepares every service of `launch`, in order; `chain` is the
/// clock chain. Fails, starting nothing, if the world file or an executable is missing.
/// `fresh` empties the services' checkpoints (a new launch; not a supervisor taking over).
pub fn prepare(
    launch: &LaunchFile,
    opts: &Options,
    chain: &[String],
    fresh: bool,
) -> Result<Vec<Slot>, SupervisorError> {
    std::fs::create_dir_all(&opts.run_dir)
        .map_err(|source| SupervisorError::RunDir { path: opts.run_dir.clone(), source })?;
    // The services' checkpoints: a fresh launch starts from nothing, a restart from its own.
    let state_dir = opts.run_dir.join(STATE_DIR);
    let emptied = if fresh { std::fs::remove_dir_all(&state_dir) } else { Ok(()) };
    let made = match emptied {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
        _ => std::fs::create_dir_all(&state_dir),
    };
    made.map_err(|source| SupervisorError::RunDir { path: state_dir.clone(), source })?;
    let vars = variables(launch, &opts.run_dir, &opts.prefix)?;
    let clock_mode = launch.settings.clock.as_str();
    // Check every binary before starting anything.
    let mut slots = Vec::new();
    for s in &launch.services {
        let mut env = vec![
            (harvey_bus::PREFIX_ENV, opts.prefix.clone()),
            (harvey_bus::CLOCK_ENV, clock_mode.to_owned()),
            (harvey_runtime::STATE_DIR_ENV, absolute(&state_dir).display().to_string()),
        ];
        if let Some(i) = chain.iter().position(|p| p == s.name()) {
            let after = &chain[(i + chain.len() - 1) % chain.len()];
            env.push((harvey_bus::PARTY_ENV, s.name().to_owned()));
            env.push((harvey_bus::AFTER_ENV, after.clone()));
        }
        let bin = s.binary_name();
        let binary = find_binary(&bin).ok_or_else(|| SupervisorError::NoBinary {
            launch: launch.path.clone(),
            service: s.name().to_owned(),
            binary: bin.clone(),
        })?;
        let args = expand_args(s, &vars);
        slots.push(Slot {
            spec: s.clone(),
            binary,
            args,
            env,
            running: None,
            policy: RestartPolicy::new(s.restart_rules()),
        });
    }
    Ok(slots)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_take_the_launch_variables() {
        let vars = [("seed", "7".to_owned()), ("run_dir", "/r".to_owned())];
        assert_eq!(substitute("--seed=${seed}", &vars), "--seed=7");
        assert_eq!(substitute("${run_dir}/drv.pty ${run_dir}", &vars), "/r/drv.pty /r");
        assert_eq!(substitute("${unknown} $seed", &vars), "${unknown} $seed");
        let vars = [("mission", "/m/a.toml".to_owned()), ("mission_dir", "/m".to_owned())];
        assert_eq!(substitute("${mission} ${mission_dir}/b.toml", &vars), "/m/a.toml /m/b.toml");
    }

    #[test]
    fn a_path_names_its_executable_and_a_name_is_looked_up() {
        assert_eq!(find_binary("/bin/sh"), Some(PathBuf::from("/bin/sh")));
        assert_eq!(find_binary("/no/such/binary"), None);
        assert!(find_binary("sh").is_some_and(|p| p.ends_with("sh") && p.is_file()));
        assert_eq!(find_binary("harvey-no-such-service"), None);
    }
}
