"""agnocast from Python: zero-copy publish/subscribe and services between processes.

Messages live in the publishing process's shared pool; fields are read and
written in place, and arrays of numbers are numpy arrays over that memory.
Message types: ``from agnocast.msg.sensor_msgs import PointCloud2``; service
types: ``from agnocast.srv.std_srvs import SetBool``.
"""
import atexit
import concurrent.futures
import inspect
import logging
import pkgutil
import time
import weakref

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
    RequestRejected,
    SchemaError,
    Sequence,
    Service,
    ServiceExists,
    ServiceUnavailable,
    SingleThreadedExecutor,
    Subscription,
    Timer,
    TooManyRequests,
    TopicWithoutSchema,
    TypeMismatch,
    VersionMismatch,
)

from ._message import Message, MessageMeta  # noqa: F401  (re-exported)
from ._service import ServiceMeta, ServiceType  # noqa: F401  (re-exported)

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


def _service_parts(srv_type):
    if not (isinstance(srv_type, type) and issubclass(srv_type, ServiceType)):
        raise TypeError(f"agnocast: {srv_type!r} is not a service type "
                        "(import one from agnocast.srv.<package>)")
    return _message_type(srv_type.Request), _message_type(srv_type.Response)


class Client(_core.Client):
    """Calls a service: each request goes to its one server, each response comes
    back to this client alone and is read in place in the server's pool.

    wait_for_service(timeout_sec=None) is True once a server is there;
    service_is_ready() says whether one is now; borrow_loaned_request() gives a
    request in this process's pool (so does Type.Request(**fields))."""

    def call(self, request, timeout_sec=None):
        """Sends the request and returns the response. Waits without the GIL and
        receives the answer itself when no executor spins the node (also from a
        callback of the node, when another thread or process serves the
        request). Raises TimeoutError after timeout_sec seconds (the
        request is forgotten then), ServiceUnavailable (no server, or it went away
        before answering), RequestRejected (the server's queue was full) or
        TooManyRequests (the client's bound of requests in flight, its QoS depth)."""
        return self._call(request, timeout_sec)

    def call_async(self, request):
        """Sends the request; returns a concurrent.futures.Future that the executor
        spinning the node completes with the response, or with the exception call()
        would raise. TooManyRequests is raised at once. Cancelling the future
        forgets the request."""
        future = concurrent.futures.Future()

        def done(response, error):
            if not future.set_running_or_notify_cancel():
                return
            if error is None:
                future.set_result(response)
            else:
                future.set_exception(error)

        request_id = self._send(request, done)
        future._agnocast_request = request_id
        # Weak: a request never answered must not keep its client alive.
        client = weakref.ref(self)

        def forget_if_cancelled(finished):
            if finished.cancelled() and client() is not None:
                client()._forget(*request_id)

        future.add_done_callback(forget_if_cancelled)
        return future

    def remove_pending_request(self, future):
        """Forgets the request of a future from call_async(): it is never completed.
        False when it was answered or failed already."""
        return self._forget(*future._agnocast_request)


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
    """A named group of publishers, subscriptions, timers, services and clients (the
    label the CLI shows).

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

    def create_service(self, srv_type, name, callback, qos=None, *, callback_group=None):
        """callback(request, response): fills the response, which is sent when it
        returns (returning it, or another response of the type, sends that one).
        Runs in the executor spinning this node. The request is read in place in the
        client's pool: one whose containers lie raises InvalidMessage where it is
        read, and is then refused unanswered, with a warning; any other exception
        stops spin(). qos: the depth of the request queue (default 1024), past which
        clients are refused. One server per name: a second raises ServiceExists."""
        request, response = _service_parts(srv_type)
        qos = _qos(qos) if qos is not None else QoS(_core.SERVICE_QUEUE_DEPTH_DEFAULT)
        service = Service(self, request, response, name, qos, callback, callback_group)
        self._entities.append(service)
        return service

    def create_client(self, srv_type, name, qos=None, *, callback_group=None):
        """A client of the service `name`; qos: its bound of requests in flight (default 10).
        Its responses are delivered by the executor spinning this node (call_async) or
        received by call() itself."""
        request, response = _service_parts(srv_type)
        qos = _qos(qos) if qos is not None else QoS(_core.CLIENT_IN_FLIGHT_DEFAULT)
        client = Client(self, request, response, name, qos, callback_group)
        self._entities.append(client)
        return client

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

    def destroy_service(self, service):
        """Lets the server go: its clients learn that what it left unanswered never
        will be (once no callback of it runs and no reference is left)."""
        self._entities.remove(service)

    def destroy_client(self, client):
        self._entities.remove(client)

    def destroy_timer(self, timer):
        timer.cancel()
        self._entities.remove(timer)

    def destroy_node(self):
        """Lets go every subscription, timer, service and client of the node (as the
        destroy_* methods); an executor spinning the node finds nothing left to run."""
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


def spin_until_future_complete(node, future, executor=None, timeout_sec=None):
    """Runs the node's callbacks until the future (from call_async) is done, or
    timeout_sec passed; True when it is done."""
    executor = executor or SingleThreadedExecutor()
    executor.add_node(node)
    deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
    try:
        while not future.done():
            left = 0.1 if deadline is None else min(0.1, deadline - time.monotonic())
            if left <= 0:
                break
            executor.spin_once(left)
    finally:
        executor.remove_node(node)
    return future.done()


def spin_once(node, timeout_sec=None, executor=None):
    """Handles one ready callback of the node, waiting up to timeout_sec; True if one ran."""
    executor = executor or SingleThreadedExecutor()
    executor.add_node(node)
    try:
        return executor.spin_once(0.0 if timeout_sec is None else timeout_sec)
    finally:
        executor.remove_node(node)
