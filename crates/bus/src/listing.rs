//! What a running domain offers, seen from outside: its topics (publish-subscribe services),
//! each with its payload's type name and the nodes attached to it (`harvey topic list`), and
//! the iceoryx2 configuration under which other iceoryx2 tools see the domain.

use iceoryx2::config::Config;
use iceoryx2::node::{NodeState, NodeView};
use iceoryx2::prelude::*;
use iceoryx2::service::static_config::messaging_pattern::MessagingPattern;

use crate::domain::domain_config;
use crate::{BusError, Result};

/// One topic of a domain.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicInfo {
    pub name: String,
    /// The payload's type name as iceoryx2 records it (`harvey_msgs/SonarRing`, `[u8]` frames).
    pub type_name: String,
    /// Names of the live nodes attached to it, sorted (a name twice: two nodes of that name).
    pub nodes: Vec<String>,
}

/// The publish-subscribe services of domain `prefix`, by name.
pub fn topics(prefix: &str) -> Result<Vec<TopicInfo>> {
    let config = domain_config(prefix)?;
    let mut out = Vec::new();
    ipc::Service::list(&config, |service| {
        if let MessagingPattern::PublishSubscribe(ps) = service.static_details.messaging_pattern() {
            let mut nodes: Vec<String> = service
                .dynamic_details
                .iter()
                .flat_map(|d| d.nodes.iter())
                .filter_map(|n| match n {
                    NodeState::Alive(view) => view.details().as_ref().map(|d| d.name().as_str().to_owned()),
                    _ => None,
                })
                .collect();
            nodes.sort();
            out.push(TopicInfo {
                name: service.static_details.name().as_str().to_owned(),
                type_name: ps.message_type_details().payload.type_name().to_string(),
                nodes,
            });
        }
        CallbackProgression::Continue
    })
    .map_err(|e| BusError::Node {
        node: "*".into(),
        detail: format!("listing the topics of `{prefix}`: {e:?}"),
    })?;
    out.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(out)
}

/// The iceoryx2 configuration (TOML) of domain `prefix`: saved as `config/iceoryx2.toml` where
/// the `iox2` command runs (the first file iceoryx2 looks for), `iox2 service list` shows the
/// domain's services.
pub fn iceoryx2_config(prefix: &str) -> Result<String> {
    let config: Config = domain_config(prefix)?;
    toml::to_string(&config).map_err(|e| BusError::Node { node: "*".into(), detail: format!("{e}") })
}
