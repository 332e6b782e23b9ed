"""Harvey's topics from Python: ctypes mirrors of its `#[repr(C)]` messages, its topic table, and
subscribers that read a running launch's topics over iceoryx2 shared memory."""

from . import msgs, topics
from .client import (
    DEFAULT_PREFIX,
    Frame,
    DomainNotFound,
    HarveyError,
    IncompatibleTopic,
    SubscriberSlotsTaken,
    Subscription,
    TopicNotFound,
    UnknownTopic,
    subscribe,
)
from .msgs import *  # noqa: F401,F403  (the message classes)

__version__ = "0.1.0"

__all__ = [
    "DEFAULT_PREFIX",
    "DomainNotFound",
    "Frame",
    "HarveyError",
    "IncompatibleTopic",
    "SubscriberSlotsTaken",
    "Subscription",
    "TopicNotFound",
    "UnknownTopic",
    "msgs",
    "subscribe",
    "topics",
] + list(msgs.ALL_TYPES)
