//! The supervisor: starts a launch file's services in order, each once the previous is ready;
//! restarts them by policy with backoff and a limit; cleans the bus after dead processes; and on
//! SIGINT/SIGTERM, or when the `end_with` service exits, stops them in reverse order.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;

use super::child::{self, Running, describe};
use super::clock::ClockWatch;
use super::config::{ClockMode, LaunchFile, Restart, Service};

/// How a launch ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// The `end_with` service exited with this code (0: the mission is done).
    Ended { service: String, code: i32 },
    /// SIGINT or SIGTERM.
    Interrupted,
    /// A service failed more often than its policy allows.
    GaveUp { service: String },
}

impl Outcome {
    /// The process exit code the CLI returns.
    pub fn exit_code(&self) -> i32 {
        match self {
            Outcome::Ended { code, .. } => *code,
            Outcome::Interrupted => 130,
            Outcome::GaveUp { .. } => 1,
        }
    }
}

/// Where and how to run a launch file.
#[derive(Debug, Clone)]
pub struct Options {
    pub prefix: String,
    pub run_dir: PathBuf,
}

struct Slot {
    spec: Service,
    binary: PathBuf,
    args: Vec<String>,
    /// The bus domain, and the service's place in the clock chain.
    env: Vec<(&'static str, String)>,
    running: Option<Running>,
    /// Exit times inside the restart window.
    failures: Vec<Instant>,
    restart_at: Option<Instant>,
}

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

fn substitute(arg: &str, vars: &[(&str, String)]) -> String {
    vars.iter().fold(arg.to_owned(), |a, (k, v)| a.replace(&format!("${{{k}}}"), v))
}

fn absolute(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_owned())
}

/// Runs a launch file to its end. Services are stopped whatever happens.
pub fn run(launch: &LaunchFile, opts: &Options) -> anyhow::Result<Outcome> {
    harvey_bus::validate_prefix(&opts.prefix)?;
    std::fs::create_dir_all(&opts.run_dir).with_context(|| format!("creating {}", opts.run_dir.display()))?;
    let mut vars = vec![
        ("run_dir", absolute(&opts.run_dir).display().to_string()),
        ("seed", launch.settings.seed.to_string()),
        ("mission", absolute(&launch.path).display().to_string()),
        ("prefix", opts.prefix.clone()),
    ];
    if let Some(w) = launch.world_path() {
        anyhow::ensure!(
            w.is_file(),
            "{}: key `launch.world`: {} does not exist",
            launch.path.display(),
            w.display()
        );
        vars.push(("world", absolute(&w).display().to_string()));
    }
    let chain = launch.clock_chain();
    let clock_mode = match launch.settings.clock {
        ClockMode::Lockstep => "lockstep",
        ClockMode::Realtime => "realtime",
    };
    // Check every binary before starting anything.
    let mut slots = Vec::new();
    for s in &launch.services {
        let mut env = vec![
            (harvey_bus::PREFIX_ENV, opts.prefix.clone()),
            (harvey_bus::CLOCK_ENV, clock_mode.to_owned()),
        ];
        if let Some(i) = chain.iter().position(|p| p == s.name()) {
            let after = &chain[(i + chain.len() - 1) % chain.len()];
            env.push((harvey_bus::PARTY_ENV, s.name().to_owned()));
            env.push((harvey_bus::AFTER_ENV, after.clone()));
        }
        let bin = s.binary_name();
        let binary = find_binary(&bin).with_context(|| {
            format!("{}: service `{}`: executable `{bin}` not found beside harvey or on PATH (build it with `cargo build --release --workspace`)", launch.path.display(), s.name())
        })?;
        let args = s.args.iter().map(|a| substitute(a, &vars)).collect();
        slots.push(Slot {
            spec: s.clone(),
            binary,
            args,
            env,
            running: None,
            failures: Vec::new(),
            restart_at: None,
        });
    }
    // Observers (tools, tests) may already be on the bus; live copies of our services may not.
    let clashes: Vec<_> = harvey_bus::live_nodes(&opts.prefix)?
        .into_iter()
        .filter(|n| n.alive && launch.services.iter().any(|s| s.name() == n.name))
        .collect();
    anyhow::ensure!(
        clashes.is_empty(),
        "bus prefix `{}` already runs {:?}: is another launch running?",
        opts.prefix,
        clashes
    );
    let cleaned = harvey_bus::cleanup_dead_nodes(&opts.prefix)?;
    if cleaned > 0 {
        tracing::info!(cleaned, prefix = %opts.prefix, "removed resources of dead nodes");
    }

    let signals = Arc::new(AtomicUsize::new(0));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register_usize(sig, Arc::clone(&signals), sig as usize)
            .context("installing signal handlers")?;
    }
    let mut clock = if chain.is_empty() { None } else { Some(ClockWatch::new(&opts.prefix, &chain)?) };
    let ready = Duration::from_millis(launch.settings.ready_timeout_ms);
    let grace = Duration::from_millis(launch.settings.grace_period_ms);

    let outcome = (|| -> anyhow::Result<Outcome> {
        for slot in slots.iter_mut() {
            if signals.load(Ordering::Relaxed) != 0 {
                return Ok(Outcome::Interrupted);
            }
            let r = child::spawn(slot.spec.name(), &slot.binary, &slot.args, &slot.env, ready)?;
            tracing::info!(service = %r.name, pid = r.child.id(), "ready");
            slot.running = Some(r);
        }
        if let Some(c) = &mut clock {
            c.start()?;
        }
        supervise(&mut slots, launch, &opts.prefix, clock.as_mut(), ready, &signals)
    })();
    shutdown(&mut slots, grace);
    drop(clock);
    match harvey_bus::retire_domain(&opts.prefix) {
        Ok(n) => tracing::debug!(removed = n, "bus domain retired"),
        Err(e) => tracing::warn!("bus domain not retired: {e}"),
    }
    outcome
}

fn supervise(
    slots: &mut [Slot],
    launch: &LaunchFile,
    prefix: &str,
    mut clock: Option<&mut ClockWatch>,
    ready: Duration,
    signals: &AtomicUsize,
) -> anyhow::Result<Outcome> {
    let end_with = launch.settings.end_with.as_ref().map(|s| s.get_ref().clone());
    loop {
        if let Some(c) = clock.as_deref_mut() {
            c.poll()?;
        }
        if signals.load(Ordering::Relaxed) != 0 {
            tracing::info!("signal received: stopping");
            return Ok(Outcome::Interrupted);
        }
        let now = Instant::now();
        for slot in slots.iter_mut() {
            let Some(r) = &mut slot.running else { continue };
            let Some(status) = r.child.try_wait().context("waiting for a child")? else { continue };
            let name = slot.spec.name().to_owned();
            slot.running = None;
            if end_with.as_deref() == Some(name.as_str()) {
                tracing::info!(service = %name, "ended with {}", describe(status));
                return Ok(Outcome::Ended { service: name, code: status.code().unwrap_or(1) });
            }
            let failed = !status.success();
            let restart = match slot.spec.restart {
                Restart::Never => false,
                Restart::OnFailure => failed,
                Restart::Always => true,
            };
            if !restart {
                tracing::warn!(service = %name, "exited with {}; not restarted (policy {:?})", describe(status), slot.spec.restart);
                continue;
            }
            let window = Duration::from_secs_f64(slot.spec.restart_window_s);
            slot.failures.retain(|t| now.duration_since(*t) < window);
            slot.failures.push(now);
            if slot.failures.len() > slot.spec.max_restarts as usize {
                tracing::error!(service = %name, "exited with {}: {} restarts within {:.0} s, giving up", describe(status), slot.spec.max_restarts, window.as_secs_f64());
                return Ok(Outcome::GaveUp { service: name });
            }
            let exp = (slot.failures.len() - 1).min(16) as u32;
            let delay = Duration::from_millis((slot.spec.backoff_ms << exp).min(slot.spec.backoff_max_ms));
            tracing::warn!(service = %name, "exited with {}: restart {} in {} ms", describe(status), slot.failures.len(), delay.as_millis());
            slot.restart_at = Some(now + delay);
        }
        for slot in slots.iter_mut() {
            if slot.restart_at.is_some_and(|t| t <= now) {
                slot.restart_at = None;
                let cleaned = harvey_bus::cleanup_dead_nodes(prefix)?;
                match child::spawn(slot.spec.name(), &slot.binary, &slot.args, &slot.env, ready) {
                    Ok(r) => {
                        tracing::info!(service = %r.name, pid = r.child.id(), cleaned, "restarted");
                        slot.running = Some(r);
                        if let Some(c) = clock.as_deref_mut() {
                            c.resume(slot.spec.name())?;
                        }
                    }
                    Err(e) => {
                        tracing::error!("{e:#}");
                        slot.failures.push(Instant::now());
                        slot.restart_at =
                            Some(Instant::now() + Duration::from_millis(slot.spec.backoff_max_ms));
                        if slot.failures.len() > slot.spec.max_restarts as usize {
                            return Ok(Outcome::GaveUp { service: slot.spec.name().to_owned() });
                        }
                    }
                }
            }
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn shutdown(slots: &mut [Slot], grace: Duration) {
    for slot in slots.iter_mut().rev() {
        if let Some(mut r) = slot.running.take() {
            let status = child::stop(&mut r, grace);
            tracing::info!(service = %r.name, "stopped: {}", describe(status));
        }
    }
}
