//! A launch file's services as parties of an in-process clock chain: the recorder's sink, the
//! registered nodes, and the master, in the chain's order; each tick the parties after the
//! master take their turns one after the other, as the bus hands the turns round.

use std::time::Instant;

use anyhow::Context;
use clap::Parser;
use harvey_runtime::End;
use harvey_runtime::node::Hosted;
use harvey_runtime::node::memory::Hub;
use harvey_supervisor::LaunchFile;

use super::registry;
use super::sink::{RecorderArgs, Sink};

/// A party of the clock chain, in process.
enum Party {
    /// The clock master (the replayer, or the bridge with the simulated DRV behind it): its
    /// turn is the runner's own.
    Master,
    Recorder,
    Node(Box<dyn Hosted>),
}

/// A service the runner runs itself (not a registered node): name, executable and arguments.
pub struct Own {
    pub name: String,
    pub binary: String,
    pub args: Vec<String>,
}

/// The launch's parties, ready to take turns.
pub struct Chain {
    parties: Vec<Party>,
    names: Vec<String>,
    /// Wall time each party's turns took, in the chain's order.
    spent: Vec<f64>,
    pub sink: Sink,
}

impl Chain {
    /// The parties of `launch` (arguments expanded with `vars`), their ports on `hub`. Services
    /// whose executable is one of `own` are the caller's to run and are returned; one of them
    /// must be the clock master.
    pub fn open(
        launch: &LaunchFile,
        vars: &[(&'static str, String)],
        hub: &Hub,
        own: &[&str],
    ) -> anyhow::Result<(Self, Vec<Own>)> {
        let mut sink = None;
        let (mut nodes, mut owned) = (Vec::new(), Vec::new());
        for s in &launch.services {
            let (name, binary, args) = (s.name(), s.binary_name(), harvey_supervisor::expand_args(s, vars));
            if own.contains(&binary.as_str()) {
                owned.push(Own { name: name.to_owned(), binary, args });
            } else if binary == "harvey-recorder" {
                let argv = std::iter::once(binary.clone()).chain(args);
                let a = RecorderArgs::try_parse_from(argv)
                    .map_err(|e| anyhow::anyhow!("service {name}: its arguments: {e}"))?;
                sink = Some((name.to_owned(), Sink::open(&a, hub)?));
            } else {
                nodes.push(registry::node(name, &binary, &args, hub)?);
            }
        }
        let path = launch.path.display();
        let (recorder, sink) = sink.ok_or_else(|| anyhow::anyhow!("{path}: no recorder"))?;
        let master = launch.settings.clock_master.as_ref().map(|m| m.get_ref().as_str());
        anyhow::ensure!(
            master.is_some_and(|m| owned.iter().any(|o| o.name == m)),
            "{path}: in process the clock master must be one of {} (a deterministic launch)",
            own.join(", ")
        );
        let mut parties = Vec::new();
        let names = launch.clock_chain();
        for party in &names {
            parties.push(match party.as_str() {
                p if Some(p) == master => Party::Master,
                p if p == recorder => Party::Recorder,
                p => {
                    let at = nodes.iter().position(|n| n.name() == p);
                    let at = at.ok_or_else(|| anyhow::anyhow!("clock party {p} is not a service"))?;
                    Party::Node(nodes.swap_remove(at))
                }
            });
        }
        let off: Vec<&str> = nodes.iter().map(|n| n.name()).collect();
        anyhow::ensure!(
            off.is_empty(),
            "services off the clock chain cannot run in process: {}",
            off.join(", ")
        );
        let spent = vec![0.0; parties.len()];
        Ok((Self { parties, names, spent, sink }, owned))
    }

    /// Every node's start, before the first tick (what they send goes out before it).
    pub fn begin(&mut self) -> anyhow::Result<()> {
        for n in self.nodes() {
            n.begin().with_context(|| format!("service {}, starting", n.name()))?;
        }
        Ok(())
    }

    /// The turns after the master's on tick `tick`, in the chain's order (a node that has
    /// finished takes none).
    pub fn turns(&mut self, tick: u64) -> anyhow::Result<()> {
        for (party, spent) in self.parties.iter_mut().zip(self.spent.iter_mut()) {
            let turn = Instant::now();
            match party {
                Party::Master => continue,
                Party::Recorder => self.sink.record_tick(tick)?,
                Party::Node(n) if !n.finished() => {
                    n.step(tick).with_context(|| format!("service {}, tick at {tick} ns", n.name()))?
                }
                Party::Node(_) => {}
            }
            *spent += turn.elapsed().as_secs_f64();
        }
        Ok(())
    }

    /// Counts `secs` of wall time to the master's turns.
    pub fn master_spent(&mut self, secs: f64) {
        if let Some(at) = self.parties.iter().position(|p| matches!(p, Party::Master)) {
            self.spent[at] += secs;
        }
    }

    /// Whether service `name` is a node that has finished.
    pub fn finished(&mut self, name: &str) -> bool {
        self.nodes().any(|n| n.name() == name && n.finished())
    }

    /// Stops every node; the exit codes, by service. A node stopped before it finished must
    /// stop cleanly.
    pub fn stop(&mut self) -> anyhow::Result<Vec<(String, u8)>> {
        let mut codes = Vec::new();
        for n in self.nodes() {
            let end = if n.finished() { End::Finished } else { End::Stopped };
            let code = n.stop(end).with_context(|| format!("service {}, stopping", n.name()))?;
            anyhow::ensure!(code == 0 || end == End::Finished, "{} stopped with code {code}", n.name());
            codes.push((n.name().to_owned(), code));
        }
        Ok(codes)
    }

    /// Wall time each party's turns took, in the chain's order.
    pub fn turn_times(&self) -> Vec<(String, f64)> {
        self.names.iter().cloned().zip(self.spent.iter().copied()).collect()
    }

    /// The recorder's sink, to finish the file.
    pub fn into_sink(self) -> Sink {
        self.sink
    }

    fn nodes(&mut self) -> impl Iterator<Item = &mut Box<dyn Hosted>> {
        self.parties.iter_mut().filter_map(|p| match p {
            Party::Node(n) => Some(n),
            _ => None,
        })
    }
}
