"""Service classes: one Python class per service type, made when its module
(agnocast/srv/<package>.py, written by agnocast_python_messages) is imported.

A service class holds the message classes of its two parts, Request and
Response, made as every message class is (agnocast._message), from the
schemas of the generated C++ types."""
from . import _message


class ServiceMeta(type):
    """The type of every service class: what a class says of its service type."""

    @property
    def type_name(cls):
        """"std_srvs/srv/SetBool"."""
        return cls._type_name

    def __repr__(cls):
        return f"<agnocast service class {cls._type_name}>"


class ServiceType(metaclass=ServiceMeta):
    """The base of every service class; Type.Request and Type.Response are its parts."""

    __slots__ = ()
    _type_name = "agnocast.ServiceType"

    def __init__(self):
        raise TypeError(f"agnocast: {type(self).__name__} is a service type; make its messages "
                        "with .Request() and .Response()")


_REQUEST = "_Request"


def define(module, name, request_schema_hex, request_defaults_hex, response_schema_hex,
           response_defaults_hex):
    """The service class `name` of a generated module, from the schema blob and
    the default-constructed bytes of each part."""
    request = _message.define(module, name + _REQUEST, request_schema_hex, request_defaults_hex)
    response = _message.define(module, name + "_Response", response_schema_hex,
                               response_defaults_hex)
    type_name = request.type_name[:-len(_REQUEST)]
    return ServiceMeta(name, (ServiceType,), {
        "__slots__": (),
        "__module__": module,
        "__qualname__": name,
        "__doc__": f"The service type {type_name}.",
        "_type_name": type_name,
        "Request": request,
        "Response": response,
    })
