"""Subscribing to a running Harvey domain from Python, as `harvey_bus` does it in Rust.

Every topic is an iceoryx2 publish-subscribe service named after the topic, plus an event
service of the same name on which publishers notify after each send. A domain is an iceoryx2
prefix (`config.global_cfg.prefix`), `harvey_` unless the launch was given another. Services
are only ever opened here, never created: a service created from Python would have iceoryx2's
default sizing, not Harvey's, and the launch would then fail to open it.

One sample is borrowed at a time: each is copied out of shared memory (a ctypes structure, or
for `camera/frame` a numpy array with its `FrameHeader`) and released before the next receive.
"""

import ctypes
import time
from dataclasses import dataclass
from typing import Any, Iterator, Optional, Union

import iceoryx2 as iox2
import numpy as np

from . import msgs
from .domain import (  # noqa: F401  (DEFAULT_PREFIX, PREFIX_ENV and the errors: re-exported)
    DEFAULT_PREFIX,
    PREFIX_ENV,
    DomainNotFound,
    HarveyError,
    IncompatibleTopic,
    SubscriberSlotsTaken,
    TopicNotFound,
    UnknownTopic,
    domain_exists,
    error_name,
    iox2_config,
    validate_prefix,
)
from .topics import Topic, lookup

NODE_NAME = "harvey-py"
# How often `wait_s` looks again for a domain or topic that is not there yet.
DISCOVERY_PERIOD_S = 0.1


@dataclass
class Frame:
    """A camera frame, copied out of shared memory: `pixels` is `(height, width)` for mono8,
    `(height, width, 3)` for rgb8; a stereo pair's has the views first, `(2, height, width)`."""

    header: msgs.FrameHeader
    pixels: np.ndarray

    @property
    def seq(self) -> int:
        return int(self.header.seq)

    @property
    def stamp_ns(self) -> int:
        return int(self.header.stamp_ns)


Received = Union[msgs.Message, Frame]


class Subscription:
    """A subscriber on one topic of a running domain, woken by the topic's event service.

    Use `messages()` (or the module's `subscribe()`), or `take()` and `wait()` in a loop of
    your own. Close it (or use it as a context manager) to leave the domain.
    """

    def __init__(
        self,
        prefix: str,
        topic: Union[str, Topic],
        *,
        wait_s: float = 0.0,
        node_name: str = NODE_NAME,
    ) -> None:
        found = lookup(topic) if isinstance(topic, str) else topic
        if found is None:
            from .topics import ALL

            raise UnknownTopic(
                f"no topic `{topic}` in Harvey's topic table; topics: {', '.join(ALL)}"
            )
        validate_prefix(prefix)
        self.topic: Topic = found
        self.prefix = prefix
        self.stopped_by_signal = False
        self._node: Any = None
        self._subscriber: Any = None
        self._listener: Any = None
        self._waitset: Any = None
        self._guard: Any = None
        iox2.set_log_level(iox2.LogLevel.Error)
        deadline = time.monotonic() + max(wait_s, 0.0)
        try:
            self._open(node_name, deadline)
        except BaseException:
            self.close()
            raise

    def _open(self, node_name: str, deadline: float) -> None:
        name = self.topic.name
        while not domain_exists(self.prefix):
            if time.monotonic() >= deadline:
                raise DomainNotFound(
                    f"no Harvey domain with prefix `{self.prefix}` on this machine: is a launch "
                    f"running with `--prefix {self.prefix}`? (the default prefix is "
                    f"`{DEFAULT_PREFIX}`)"
                )
            time.sleep(DISCOVERY_PERIOD_S)
        self._node = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new(node_name))
            .config(iox2_config(self.prefix))
            .create(iox2.ServiceType.Ipc)
        )
        service_name = iox2.ServiceName.new(name)
        qos = self.topic.qos
        while True:
            try:
                builder = self._node.service_builder(service_name)
                if self.topic.frames:
                    builder = builder.publish_subscribe(iox2.Slice[ctypes.c_uint8]).user_header(
                        msgs.FrameHeader
                    )
                else:
                    builder = builder.publish_subscribe(self.topic.payload)
                service = (
                    builder.history_size(qos.history)
                    .subscriber_max_buffer_size(qos.buffer)
                    .subscriber_max_borrowed_samples(qos.borrowed)
                    .enable_safe_overflow(True)
                    .max_publishers(qos.max_publishers)
                    .max_subscribers(qos.max_subscribers)
                    .max_nodes(qos.max_nodes)
                    .open()
                )
                break
            except iox2.PublishSubscribeOpenError as e:
                why = error_name(e)
                if why == "DoesNotExist" and time.monotonic() < deadline:
                    time.sleep(DISCOVERY_PERIOD_S)
                    continue
                if why == "DoesNotExist":
                    raise TopicNotFound(
                        f"domain `{self.prefix}` has no topic `{name}` (yet): no service of the "
                        "launch has opened it"
                    ) from None
                if "Incompatible" in why or "DoesNotSupport" in why:
                    payload = "[u8] with FrameHeader" if self.topic.frames else self.topic.payload.type_name()
                    raise IncompatibleTopic(
                        f"topic `{name}` of domain `{self.prefix}` is not what this package "
                        f"expects ({why}): {payload}, QoS {qos}; is harvey_client as new as "
                        "the launch?"
                    ) from None
                raise HarveyError(f"cannot open topic `{name}` of `{self.prefix}`: {why}") from None
        try:
            self._subscriber = service.subscriber_builder().buffer_size(qos.buffer).create()
        except iox2.SubscriberCreateError as e:
            why = error_name(e)
            if "ExceedsMaxSupportedSubscribers" in why:
                raise SubscriberSlotsTaken(
                    f"all {qos.max_subscribers} subscriber slots of `{name}` are taken"
                ) from None
            raise HarveyError(f"cannot subscribe to `{name}`: {why}") from None
        self._listener = self._listen(service_name, deadline)
        self._waitset = iox2.WaitSetBuilder.new().create(iox2.ServiceType.Ipc)
        self._guard = self._waitset.attach_notification(self._listener)

    def _listen(self, service_name: Any, deadline: float) -> Any:
        """The listener to the topic's wake-ups. A publisher creates its topic's event service
        just after the topic itself: a subscriber that found the topic may be a moment early for
        its wake-ups, so it waits for them until `deadline`, and a second even when not asked to."""
        name, qos = self.topic.name, self.topic.qos
        wakeups_by = max(deadline, time.monotonic() + 1.0)
        while True:
            try:
                event = (
                    self._node.service_builder(service_name)
                    .event()
                    .max_notifiers(qos.max_publishers)
                    .max_listeners(qos.max_subscribers)
                    .max_nodes(qos.max_nodes)
                    .open()
                )
                return event.listener_builder().create()
            except (iox2.EventOpenError, iox2.ListenerCreateError) as e:
                why = error_name(e)
                if why == "DoesNotExist" and time.monotonic() < wakeups_by:
                    time.sleep(DISCOVERY_PERIOD_S)
                    continue
                raise HarveyError(f"cannot listen to the wake-ups of `{name}`: {why}") from None

    def take(self) -> Optional[Received]:
        """The oldest queued message, copied out of shared memory, or None when none is queued.
        Pending wake-ups are consumed before None is reported, so a message sent later wakes
        `wait()` again."""
        got = self._receive()
        if got is None:
            self._listener.try_wait()
            got = self._receive()
        return got

    def _receive(self) -> Optional[Received]:
        sample = self._subscriber.receive()
        if sample is None:
            return None
        try:
            if self.topic.frames:
                return _frame(sample)
            out = self.topic.payload()
            ctypes.memmove(ctypes.byref(out), sample.payload_ptr, ctypes.sizeof(out))
            return out
        finally:
            # Release the borrowed sample before the next receive.
            sample.delete()

    def wait(self, timeout_s: Optional[float]) -> bool:
        """Sleeps until the topic's publishers notify or `timeout_s` passes (None: no timeout).
        False when it timed out or a signal (SIGINT, SIGTERM) asked to stop; `stopped_by_signal`
        tells which."""
        if timeout_s is None:
            notifications, result = self._waitset.wait_and_process()
        else:
            timeout = iox2.Duration.from_secs_f64(max(timeout_s, 0.0))
            notifications, result = self._waitset.wait_and_process_with_timeout(timeout)
        if result in (iox2.WaitSetRunResult.Interrupt, iox2.WaitSetRunResult.TerminationRequest):
            self.stopped_by_signal = True
            return False
        return len(notifications) > 0

    def messages(
        self, count: Optional[int] = None, timeout_s: Optional[float] = None
    ) -> Iterator[Received]:
        """Yields messages as they come until `count` have come, `timeout_s` has passed, or a
        signal asks to stop."""
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        n = 0
        while count is None or n < count:
            msg = self.take()
            if msg is not None:
                n += 1
                yield msg
                continue
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                return
            if not self.wait(remaining) and self.stopped_by_signal:
                return

    def close(self) -> None:
        """Leaves the domain: detaches and drops the ports and the node."""
        for name in ("_guard", "_waitset", "_listener", "_subscriber"):
            port = getattr(self, name)
            setattr(self, name, None)
            if port is not None and hasattr(port, "delete"):
                port.delete()
        self._node = None

    def __enter__(self) -> "Subscription":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _frame(sample: Any) -> Frame:
    header = msgs.FrameHeader()
    ctypes.memmove(ctypes.byref(header), sample.user_header_ptr, ctypes.sizeof(header))
    payload = sample.payload()
    n = payload.len()
    raw = np.frombuffer((ctypes.c_uint8 * n).from_address(payload.as_ptr()), dtype=np.uint8).copy()
    bpp = msgs.BYTES_PER_PIXEL.get(header.encoding)
    h, w, stride, views = header.height_px, header.width_px, header.stride_bytes, header.view_count()
    if bpp is None or stride < w * bpp or n != stride * h * views:
        raise HarveyError(
            f"frame {header.seq}: {n} bytes do not hold {views} view(s) of {w}x{h} of encoding "
            f"{header.encoding} in rows of {stride} bytes"
        )
    rows = raw.reshape(h * views, stride)[:, : w * bpp]
    shape = (h, w) if bpp == 1 else (h, w, bpp)
    if views > 1:
        shape = (views, *shape)
    return Frame(header=header, pixels=np.ascontiguousarray(rows).reshape(shape))


def subscribe(
    prefix: str,
    topic: Union[str, Topic],
    count: Optional[int] = None,
    timeout_s: Optional[float] = None,
    wait_s: float = 0.0,
) -> Iterator[Received]:
    """Yields the messages of `topic` in domain `prefix` until `count` have come or `timeout_s`
    has passed. Waits up to `wait_s` for the domain and topic to appear; raises a `HarveyError`
    when they do not (`DomainNotFound`, `TopicNotFound`, `UnknownTopic` ...)."""
    with Subscription(prefix, topic, wait_s=wait_s) as sub:
        yield from sub.messages(count=count, timeout_s=timeout_s)
