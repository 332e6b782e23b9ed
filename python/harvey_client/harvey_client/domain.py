"""A Harvey domain as `harvey_bus` makes it: its prefix, whether its shared memory exists, the
iceoryx2 configuration that opens it, and the errors of finding a domain or topic not as Harvey
makes it."""

import os
import re
from typing import Any

import iceoryx2 as iox2

DEFAULT_PREFIX = "harvey_"
PREFIX_ENV = "HARVEY_IPC_PREFIX"
SHM_DIR = "/dev/shm"


class HarveyError(Exception):
    """Something about the domain or topic asked for is not as Harvey makes it."""


class UnknownTopic(HarveyError):
    """The name is not in Harvey's topic table."""


class DomainNotFound(HarveyError):
    """No domain with this prefix has shared memory on this machine (wrong prefix, or no launch)."""


class TopicNotFound(HarveyError):
    """The domain exists but offers no such service (nobody has opened the topic yet)."""


class IncompatibleTopic(HarveyError):
    """The service exists with another type or sizing (this package and Harvey disagree)."""


class SubscriberSlotsTaken(HarveyError):
    """Every subscriber slot of the topic is taken."""


def validate_prefix(prefix: str) -> None:
    """As `harvey_bus::validate_prefix`: 1 to 40 ASCII letters, digits, `_` or `-`."""
    if not re.fullmatch(r"[A-Za-z0-9_-]{1,40}", prefix):
        raise HarveyError(
            f"bad prefix `{prefix}`: 1 to 40 ASCII letters, digits, `_` or `-` are allowed"
        )


def domain_exists(prefix: str) -> bool:
    """Whether shared memory of domain `prefix` exists (as `harvey_bus` `shm.rs`: iceoryx2 names
    each object `<prefix><40 hex digits>_...`). True where /dev/shm cannot be read."""
    if not os.path.isdir(SHM_DIR):
        return True
    pattern = re.compile(re.escape(prefix) + r"[0-9a-f]{40}_")
    return any(pattern.match(name) for name in os.listdir(SHM_DIR))


def iox2_config(prefix: str) -> Any:
    """The iceoryx2 configuration of domain `prefix`."""
    config = iox2.config.global_config()
    config.global_cfg.prefix = iox2.FileName.new(prefix)
    return config


def error_name(e: Exception) -> str:
    """The iceoryx2 error variant an exception carries (`DoesNotExist`, ...)."""
    return str(e.args[0]) if e.args else repr(e)
