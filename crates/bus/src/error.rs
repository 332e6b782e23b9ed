//! The bus's error type: every failure names the topic (or node) and what was being done.

/// A bus failure, naming the topic or node it concerns.
#[derive(Debug, thiserror::Error)]
pub enum BusError {
    #[error("invalid bus prefix `{prefix}`: {reason}")]
    BadPrefix { prefix: String, reason: &'static str },
    #[error("cannot join the bus as node `{node}`: {detail}")]
    Node { node: String, detail: String },
    #[error("topic `{topic}`: {what}: {detail}")]
    Topic { topic: String, what: &'static str, detail: String },
    #[error(
        "topic `{topic}` exists with another payload type or incompatible sizing \
         (is a stale or foreign process using this prefix?): {detail}"
    )]
    IncompatibleTopic { topic: String, detail: String },
    #[error(
        "topic `{topic}`: all {max} subscriber slots are taken, by the nodes attached to it: {}",
        holders.join(", ")
    )]
    SubscribersFull { topic: String, max: usize, holders: Vec<String> },
    #[error("waitset: {0}")]
    Wait(String),
}

impl BusError {
    pub(crate) fn topic(topic: &str, what: &'static str, err: impl core::fmt::Debug) -> Self {
        BusError::Topic { topic: topic.to_owned(), what, detail: format!("{err:?}") }
    }

    /// A subscriber that could not be created: when the topic's slots are all taken, the error
    /// names the nodes attached to it (publishers among them), so a user sees who holds them.
    pub(crate) fn subscriber(prefix: &str, topic: &str, max: usize, err: impl core::fmt::Debug) -> Self {
        let detail = format!("{err:?}");
        if !detail.contains("ExceedsMaxSupportedSubscribers") {
            return BusError::Topic { topic: topic.to_owned(), what: "cannot create a subscriber", detail };
        }
        let holders = match crate::listing::topics(prefix) {
            Ok(topics) => topics.into_iter().find(|t| t.name == topic).map(|t| t.nodes).unwrap_or_default(),
            Err(e) => vec![format!("(could not list them: {e})")],
        };
        BusError::SubscribersFull { topic: topic.to_owned(), max, holders }
    }
}
