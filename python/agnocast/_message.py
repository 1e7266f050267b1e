"""Helpers for the generated message modules (agnocast/msg/<package>.py)."""
from ._core import MessageType


def define(module, name, schema_hex, defaults_hex=""):
    """The message type `name` of a generated module, from its schema blob and
    the bytes of a default-constructed message (its default values)."""
    message_type = MessageType(bytes.fromhex(schema_hex), bytes.fromhex(defaults_hex))
    message_type.__name__ = name
    message_type.__qualname__ = name
    message_type.__module__ = module
    return message_type
