"""Message types, one module per message package: ``from agnocast.msg.std_msgs import String``.

Each type is an agnocast.MessageType made from the schema its generated C++
type has, so Python and C++ endpoints of one type share name, hash and layout.
"""
import pkgutil

# User packages (agnocast_generate_messages(... PYTHON)) install their modules
# into agnocast/msg folders of other sys.path entries.
__path__ = pkgutil.extend_path(__path__, __name__)
