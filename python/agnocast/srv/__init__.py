"""Service types, one module per package: ``from agnocast.srv.std_srvs import SetBool``.

Each type is a class with the message classes Request and Response, made
from the schemas their generated C++ types have, so Python and C++ servers
and clients of one service type meet on its topics.
"""
import pkgutil

# User packages (agnocast_generate_messages(... PYTHON)) install their modules
# into agnocast/srv folders of other sys.path entries.
__path__ = pkgutil.extend_path(__path__, __name__)
