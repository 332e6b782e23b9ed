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
    #[error("waitset: {0}")]
    Wait(String),
}

impl BusError {
    pub(crate) fn topic(topic: &str, what: &'static str, err: impl core::fmt::Debug) -> Self {
        BusError::Topic { topic: topic.to_owned(), what, detail: format!("{err:?}") }
    }
}
