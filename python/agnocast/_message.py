"""Message classes: one Python class per message type, made when its module
(agnocast/msg/<package>.py, written by agnocast_python_messages) is imported.

Every class derives from agnocast.Message, whose compiled core reads and
writes fields in place at the offsets of the C++ type's schema; nothing is
compiled per type."""
import importlib

from . import _core


_CoreMeta = type(_core.Message)  # pybind11's metaclass


class MessageMeta(_CoreMeta):
    """The type of every message class: what a class says of its message type.

    These are properties of the class, not of its messages, so that they never
    hide a field (PointCloud2.fields is the list of field names, msg.fields the field)."""

    def __setattr__(cls, name, value):
        if name in cls.__dict__.get("_constants", ()):
            raise AttributeError(f"{cls.__name__}.{name} is a constant of the .msg file")
        super().__setattr__(name, value)

    def __delattr__(cls, name):
        if name in cls.__dict__.get("_constants", ()):
            raise AttributeError(f"{cls.__name__}.{name} is a constant of the .msg file")
        super().__delattr__(name)

    @property
    def type_name(cls):
        """"sensor_msgs/msg/PointCloud2"."""
        return cls._type_name

    @property
    def type_hash(cls):
        """The layout hash the kernel compares on a topic."""
        return cls._type_hash

    @property
    def fields(cls):
        """The field names, in .msg order."""
        return _type_of(cls).fields

    @property
    def constants(cls):
        """The .msg file's constants as {name: value}."""
        return {name: cls.__dict__[name] for name in cls.__dict__.get("_constants", ())}

    @property
    def definition(cls):
        """The .msg text of the type and of every type it uses, as rosbag2 writes it."""
        return _type_of(cls).definition

    @property
    def schema(cls):
        """The schema blob of the C++ type (the one the kernel keeps per topic)."""
        return _type_of(cls).schema

    def __repr__(cls):
        return f"<agnocast message class {cls._type_name}>"


def _type_of(cls):
    message_type = cls.__dict__.get("_agnocast_type")
    if message_type is None:
        raise TypeError(f"agnocast: {cls.__name__} is known only as a part of another message; "
                        f"import agnocast.msg.{cls._type_name.split('/')[0]} for its own type")
    return message_type


class Message(_core.Message, metaclass=MessageMeta):
    """A message of the pool, read and written in place; the base of every message class.

    Type(**fields) makes a new message in this process's pool, ready to publish
    with any publisher of its type (like borrow_loaned_message()); fields not
    given keep the .msg file's default values."""

    __slots__ = ()
    _type_name = "agnocast.Message"
    _type_hash = 0

    def __init__(self, **fields):
        message_type = type(self).__dict__.get("_agnocast_type")
        if message_type is None:
            if type(self) is not Message:
                _type_of(type(self))  # raises, saying which module to import
            raise TypeError("agnocast: Message is the base of the message classes; make a "
                            "message of one (agnocast.msg.<package>.<Type>())")
        super().__init__(message_type.new_message())
        for name, value in fields.items():
            setattr(self, name, value)


def _make_class(module, name, type_name, type_hash, message_type):
    cls = MessageMeta(name, (Message,), {
        "__slots__": (),
        "__module__": module,
        "__qualname__": name,
        "__doc__": f"The message type {type_name}.",
        "_type_name": type_name,
        "_type_hash": type_hash,
        "_agnocast_type": message_type,
        "_constants": (),
    })
    _core.register_class(type_hash, cls)
    return cls


def define(module, name, schema_hex, defaults_hex=""):
    """The message class `name` of a generated module, from its schema blob and
    the bytes of a default-constructed message (its default values)."""
    message_type = _core.MessageType(bytes.fromhex(schema_hex), bytes.fromhex(defaults_hex))
    return _make_class(module, name, message_type.type_name, message_type.type_hash, message_type)


def constant(cls, name, value):
    """Adds a constant of the .msg file to a generated class (read-only from then on)."""
    _CoreMeta.__setattr__(cls, "_constants", cls.__dict__["_constants"] + (name,))
    _CoreMeta.__setattr__(cls, name, value)


def class_for(type_name, type_hash):
    """The class of a nested message whose class was not made yet (called by the
    core): its package's module, imported now, or else a class for this type alone."""
    package, _, name = type_name.rpartition("/")
    package = package.split("/")[0]
    try:
        importlib.import_module(f"agnocast.msg.{package}")
    except ImportError:
        pass
    found = _core.registered_class(type_hash)
    if found is not None:
        return found
    return _make_class(f"agnocast.msg.{package}", name, type_name, type_hash, None)
