"""agnocast from Python: zero-copy publish/subscribe between processes.

Messages live in the publishing process's shared pool; fields are read and
written in place, and arrays of numbers are numpy arrays over that memory.
Message types: ``from agnocast.msg.sensor_msgs import PointCloud2``.
"""
import atexit
import inspect
import logging
import pkgutil

# Message modules of other packages (agnocast_generate_messages(... PYTHON))
# may sit in agnocast/msg folders of other sys.path entries.
__path__ = pkgutil.extend_path(__path__, __name__)

from . import _core
from ._core import (  # noqa: F401  (re-exported)
    AccessDenied,
    CallbackGroup,
    CallbackGroupType,
    DeviceError,
    Error,
    Executor,
    InvalidMessage,
    MessagePublished,
    MessageType,
    ModuleNotLoaded,
    MultiThreadedExecutor,
    PollingSubscriber,
    PoolExhausted,
    Publisher,
    QoS,
    QueueError,
    ReadOnlyMessage,
    SchemaError,
    Sequence,
    SingleThreadedExecutor,
    Subscription,
    Timer,
    TopicWithoutSchema,
    TypeMismatch,
    VersionMismatch,
)

from ._message import Message, MessageMeta  # noqa: F401  (re-exported)

# The topic access policy's refusal, under the name other frameworks use.
PermissionDenied = AccessDenied

_logger = logging.getLogger("agnocast")
_levels = {
    _core.LOG_DEBUG: logging.DEBUG,
    _core.LOG_INFO: logging.INFO,
    _core.LOG_WARNING: logging.WARNING,
    _core.LOG_ERROR: logging.ERROR,
}


def _log(level, text):
    _logger.log(_levels.get(level, logging.WARNING), text)


# The library's warnings go to the logger "agnocast", from a thread of the
# binding's own (the library may log while it holds a lock that a thread
# with the GIL waits for); at exit, what is left is handed over first.
_core.set_log_handler(_log)
atexit.register(_core.set_log_handler, None)


class MessageInfo:
    """What a subscription learns about a message besides its content."""

    __slots__ = ("publisher_id", "entry_id", "publish_time", "bytes")

    def __init__(self, publisher_id, entry_id, publish_time, bytes):  # noqa: A002
        self.publisher_id = publisher_id
        self.entry_id = entry_id
        self.publish_time = publish_time  # steady clock, nanoseconds
        self.bytes = bytes

    def __repr__(self):
        return (f"MessageInfo(publisher_id={self.publisher_id}, entry_id={self.entry_id}, "
                f"publish_time={self.publish_time}, bytes={self.bytes})")


class MutuallyExclusiveCallbackGroup(CallbackGroup):
    """Callbacks of the group never run at the same time, whatever the executor's threads."""

    def __init__(self):
        super().__init__(CallbackGroupType.MutuallyExclusive)


class ReentrantCallbackGroup(CallbackGroup):
    """Callbacks of the group may run in parallel on a MultiThreadedExecutor (a
    subscription still delivers its own messages one at a time, in order)."""

    def __init__(self):
        super().__init__(CallbackGroupType.Reentrant)


def _qos(qos):
    if isinstance(qos, QoS):
        return qos
    if isinstance(qos, int):
        return QoS(qos)
    raise TypeError(f"agnocast: qos must be an agnocast.QoS or a depth, not {qos!r}")


def _message_type(msg_type):
    found = getattr(msg_type, "_agnocast_type", msg_type)
    if not isinstance(found, MessageType):
        raise TypeError(f"agnocast: {msg_type!r} is not a message type "
                        "(import one from agnocast.msg.<package>)")
    return found


def _takes_info(callback):
    try:
        parameters = inspect.signature(callback).parameters.values()
    except (TypeError, ValueError):
        return False
    positional = [p for p in parameters
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    variadic = any(p.kind == p.VAR_POSITIONAL for p in parameters)
    return variadic or len(positional) >= 2


class Node(_core.Node):
    """A named group of publishers, subscriptions and timers (the label the CLI shows).

    The node keeps what it created alive until destroy_* or the node goes."""

    def __init__(self, name):
        super().__init__(name)
        self._entities = []

    def create_publisher(self, msg_type, topic, qos):
        return Publisher(self, _message_type(msg_type), topic, _qos(qos))

    def create_subscription(self, msg_type, topic, qos, callback, *,
                            ignore_local_publications=False, callback_group=None):
        """callback(msg) or callback(msg, info): runs in the executor spinning this node,
        in callback_group (None: the node's default group, mutually exclusive)."""
        if _takes_info(callback):
            def deliver(message, info):
                callback(message, MessageInfo(**info))
        else:
            def deliver(message, _info):
                callback(message)
        subscription = Subscription(self, _message_type(msg_type), topic, _qos(qos), deliver,
                                    ignore_local_publications, callback_group)
        self._entities.append(subscription)
        return subscription

    def create_polling_subscriber(self, msg_type, topic, qos, *,
                                  ignore_local_publications=False):
        return PollingSubscriber(self, _message_type(msg_type), topic, _qos(qos),
                                 ignore_local_publications)

    def create_wall_timer(self, period_sec, callback, callback_group=None):
        """callback() every period_sec seconds (steady clock), from the executor,
        in callback_group (None: the node's default group)."""
        timer = Timer(self, float(period_sec), callback, callback_group)
        self._entities.append(timer)
        return timer

    create_timer = create_wall_timer

    def destroy_subscription(self, subscription):
        """Lets the subscription go: it is removed once no callback of it runs
        (at once, unless an executor is running one) and no reference is left."""
        self._entities.remove(subscription)

    def destroy_timer(self, timer):
        timer.cancel()
        self._entities.remove(timer)

    def destroy_node(self):
        """Lets go every subscription and timer of the node (as destroy_subscription
        and destroy_timer); an executor spinning the node finds nothing left to run."""
        for entity in self._entities:
            if isinstance(entity, Timer):
                entity.cancel()
        self._entities.clear()


def spin(node, executor=None):
    """Runs the node's callbacks until SIGINT/SIGTERM (KeyboardInterrupt) or cancel()."""
    executor = executor or SingleThreadedExecutor()
    executor.add_node(node)
    try:
        executor.spin()
    finally:
        executor.remove_node(node)


def spin_once(node, timeout_sec=None, executor=None):
    """Handles one ready callback of the node, waiting up to timeout_sec; True if one ran."""
    executor = executor or SingleThreadedExecutor()
    executor.add_node(node)
    try:
        return executor.spin_once(0.0 if timeout_sec is None else timeout_sec)
    finally:
        executor.remove_node(node)
