//! A process's membership in a bus domain (an iceoryx2 node with a prefix), and the
//! supervisor's view of a domain: which nodes live, and cleaning up after dead ones.

use iceoryx2::config::Config;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;

use crate::{BusError, Result};

/// Environment variable through which the supervisor hands a domain prefix to its services.
pub const PREFIX_ENV: &str = "HARVEY_IPC_PREFIX";
/// Prefix used when no other is given.
pub const DEFAULT_PREFIX: &str = "harvey_";

/// Whether `name` is plain: not empty, ASCII letters, digits, `-` and `_` only (a bus prefix, a
/// service's or a host's name).
pub fn is_plain_name(name: &str) -> bool {
    !name.is_empty() && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

/// Checks that a prefix can name shared-memory objects and files: 1–40 ASCII letters, digits,
/// `_` or `-`.
pub fn validate_prefix(prefix: &str) -> Result<()> {
    let bad = |reason| Err(BusError::BadPrefix { prefix: prefix.to_owned(), reason });
    if prefix.is_empty() || prefix.len() > 40 {
        return bad("must be 1 to 40 characters long");
    }
    if !is_plain_name(prefix) {
        return bad("only ASCII letters, digits, `_` and `-` are allowed");
    }
    Ok(())
}

pub(crate) fn domain_config(prefix: &str) -> Result<Config> {
    validate_prefix(prefix)?;
    let mut config = Config::default();
    config.global.prefix = FileName::new(prefix.as_bytes()).map_err(|_| BusError::BadPrefix {
        prefix: prefix.to_owned(),
        reason: "rejected by iceoryx2 as a file name",
    })?;
    Ok(config)
}

/// One process's connection to a bus domain. Create ports from it; drop it last.
pub struct Bus {
    pub(crate) node: Node<ipc::Service>,
    pub(crate) prefix: String,
    /// This process's publishers, re-offered when the supervisor asks (`reoffer.rs`).
    pub(crate) reoffers: std::rc::Rc<crate::reoffer::Reoffers>,
}

impl Bus {
    /// Joins the domain named by `$HARVEY_IPC_PREFIX` (or [`DEFAULT_PREFIX`]) as node `name`.
    pub fn join(name: &str) -> Result<Self> {
        let prefix = std::env::var(PREFIX_ENV).unwrap_or_else(|_| DEFAULT_PREFIX.to_owned());
        Self::join_with_prefix(name, &prefix)
    }

    /// Joins the domain `prefix` as node `name`. Stale resources of dead nodes of this domain
    /// are removed on the way in.
    pub fn join_with_prefix(name: &str, prefix: &str) -> Result<Self> {
        iceoryx2::prelude::set_log_level(LogLevel::Error);
        let config = domain_config(prefix)?;
        let fail = |detail: String| BusError::Node { node: name.to_owned(), detail };
        let node_name = NodeName::new(name).map_err(|e| fail(format!("{e:?}")))?;
        let node = NodeBuilder::new()
            .name(&node_name)
            .config(&config)
            .create::<ipc::Service>()
            .map_err(|e| fail(format!("{e:?}")))?;
        // The node has opened or created the domain's management segment: keep it private.
        crate::shm::make_private(prefix);
        let reoffers = std::rc::Rc::new(crate::reoffer::Reoffers::new(&node)?);
        Ok(Self { node, prefix: prefix.to_owned(), reoffers })
    }

    /// What wakes this process when the supervisor asks it to re-offer its publishers' history
    /// to a restarted subscriber; attach it to the loop's waiter and call [`Bus::serve_reoffers`]
    /// on each wake-up ([`crate::Pace`] does both).
    pub fn reoffers(&self) -> std::rc::Rc<crate::reoffer::Reoffers> {
        self.reoffers.clone()
    }

    /// Answers the supervisor's pending re-offer requests; returns how many.
    pub fn serve_reoffers(&self) -> Result<usize> {
        self.reoffers.serve()
    }

    pub fn prefix(&self) -> &str {
        &self.prefix
    }

    pub fn node_name(&self) -> String {
        self.node.name().as_str().to_owned()
    }

    pub(crate) fn service_name(topic: &str) -> Result<ServiceName> {
        ServiceName::new(topic).map_err(|e| BusError::topic(topic, "invalid topic name", e))
    }
}

/// A node seen in a domain.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeInfo {
    pub name: String,
    pub pid: i32,
    pub alive: bool,
}

/// Lists the nodes of a domain, alive and dead.
pub fn live_nodes(prefix: &str) -> Result<Vec<NodeInfo>> {
    let config = domain_config(prefix)?;
    let mut nodes = Vec::new();
    Node::<ipc::Service>::list(&config, |state| {
        let (view_details, alive) = match &state {
            NodeState::Alive(view) => (view.details().clone(), true),
            NodeState::Dead(view) => (view.details().clone(), false),
            NodeState::Inaccessible(_) | NodeState::Undefined(_) => (None, false),
        };
        if let Some(d) = view_details {
            nodes.push(NodeInfo { name: d.name().as_str().to_owned(), pid: d.process_id().value(), alive });
        }
        CallbackProgression::Continue
    })
    .map_err(|e| BusError::Node { node: "*".into(), detail: format!("listing nodes: {e:?}") })?;
    Ok(nodes)
}

/// Removes the shared memory and files left by dead nodes of a domain (a process killed with
/// SIGKILL leaves its segments behind). Returns how many dead nodes were cleaned.
pub fn cleanup_dead_nodes(prefix: &str) -> Result<usize> {
    let config = domain_config(prefix)?;
    let mut cleaned = 0;
    let mut failures = Vec::new();
    Node::<ipc::Service>::list(&config, |state| {
        if let NodeState::Dead(view) = state {
            match view.try_remove_stale_resources() {
                Ok(()) => cleaned += 1,
                Err(e) => failures.push(format!("{e:?}")),
            }
        }
        CallbackProgression::Continue
    })
    .map_err(|e| BusError::Node { node: "*".into(), detail: format!("listing nodes: {e:?}") })?;
    if !failures.is_empty() {
        tracing::warn!(prefix, ?failures, "some dead nodes could not be cleaned");
    }
    Ok(cleaned)
}

/// Removes every trace of a domain once none of its nodes lives: dead nodes' resources, then the
/// shared-memory objects iceoryx2 keeps per prefix (its global management segment). Only this
/// domain's objects: not those of another domain whose prefix starts with this one. Refuses
/// while a node is alive. Returns how many shared-memory objects were removed.
pub fn retire_domain(prefix: &str) -> Result<usize> {
    let alive: Vec<NodeInfo> = live_nodes(prefix)?.into_iter().filter(|n| n.alive).collect();
    if !alive.is_empty() {
        return Err(BusError::Node {
            node: alive.iter().map(|n| n.name.as_str()).collect::<Vec<_>>().join(", "),
            detail: format!("still alive in domain `{prefix}`"),
        });
    }
    cleanup_dead_nodes(prefix)?;
    let removed = crate::shm::domain_files(prefix).iter().filter(|f| std::fs::remove_file(f).is_ok()).count();
    Ok(removed)
}
