"""The message and service classes as Python sees them, without the kernel module (run natively).

What needs messages in a pool (isinstance of received and loaned messages) is
in test_agnocast.py, in the VM."""
import pytest

import agnocast
from agnocast.msg.geometry_msgs import Vector3
from agnocast.msg.sensor_msgs import NavSatStatus, PointCloud2, PointField
from agnocast.msg.std_msgs import Header, String
from agnocast.msg.wheel_msgs import Wheel
from agnocast.srv.example_interfaces import AddTwoInts
from agnocast.srv.std_srvs import Empty, SetBool, Trigger
from agnocast.srv.wheel_msgs import Rate


def test_constants_are_the_msg_files():
    assert (PointField.INT8, PointField.UINT8, PointField.FLOAT32, PointField.FLOAT64) == (1, 2, 7, 8)
    assert (NavSatStatus.STATUS_UNKNOWN, NavSatStatus.STATUS_FIX) == (-2, 0)
    assert NavSatStatus.SERVICE_GALILEO == 8
    assert PointField.constants == {"INT8": 1, "UINT8": 2, "INT16": 3, "UINT16": 4, "INT32": 5,
                                    "UINT32": 6, "FLOAT32": 7, "FLOAT64": 8}
    assert PointCloud2.constants == {}


def test_constants_of_a_user_package_keep_their_types_and_text():
    assert Wheel.MODE_REVERSE == -1
    assert Wheel.MAX_SPEED == 2.5 and isinstance(Wheel.MAX_SPEED, float)
    assert Wheel.RADIUS == 0.3  # the .msg file's text, not a float32's neighbour
    assert Wheel.DRIVEN is True
    assert Wheel.ODOMETER_MAX == 2**64 - 1
    assert Wheel.LABEL == 'front "left" \\ wheel'
    assert Wheel.GREETING == "grüße"
    assert list(Wheel.constants) == ["MODE_REVERSE", "MAX_SPEED", "RADIUS", "DRIVEN",
                                     "ODOMETER_MAX", "LABEL", "GREETING"]


def test_definition_is_the_msg_files_own_text():
    text = Wheel.definition
    assert text.startswith("# A user message for the Python interop tests.\n"
                           "int8 MODE_REVERSE=-1\nfloat32 MAX_SPEED=2.5\n")
    assert 'string GREETING="grüße"\n' in text
    assert "\n" + "=" * 80 + "\nMSG: std_msgs/Header\n" in text
    assert PointField.definition.startswith("# How one field of each point is laid out in "
                                            "PointCloud2.data.\n\n# Values of datatype\n"
                                            "uint8 INT8=1\n")


def test_constants_are_read_only():
    with pytest.raises(AttributeError):
        PointField.FLOAT32 = 9
    with pytest.raises(AttributeError):
        del PointField.FLOAT32
    assert PointField.FLOAT32 == 7


def test_types_are_classes_named_after_their_messages():
    for cls, name in [(PointCloud2, "sensor_msgs/msg/PointCloud2"), (Header, "std_msgs/msg/Header"),
                      (Wheel, "wheel_msgs/msg/Wheel")]:
        assert isinstance(cls, type) and issubclass(cls, agnocast.Message)
        assert cls.__name__ == name.rsplit("/", 1)[1]
        assert cls.__module__ == "agnocast.msg." + name.split("/")[0]
        assert cls.type_name == name
        assert cls.type_hash != 0
    assert PointCloud2.fields == ["header", "height", "width", "fields", "is_bigendian",
                                  "point_step", "row_step", "data", "is_dense"]
    assert String.type_hash != Header.type_hash
    assert not issubclass(String, PointCloud2)
    assert repr(Vector3) == "<agnocast message class geometry_msgs/msg/Vector3>"


def test_a_class_property_never_hides_a_field():
    # PointCloud2.fields is the list of names; a message's .fields is its field,
    # which the class leaves to the message (no class attribute of that name).
    assert "fields" not in PointCloud2.__dict__ and "fields" not in agnocast.Message.__dict__


def test_the_base_class_makes_no_message():
    with pytest.raises(TypeError, match="base of the message classes"):
        agnocast.Message()


def test_a_type_that_is_not_a_message_class_is_refused():
    node = agnocast.Node("py_not_a_type")
    with pytest.raises(TypeError, match="not a message type"):
        node.create_publisher(int, "/py/not_a_type", 1)
    with pytest.raises(TypeError, match="not a message type"):
        node.create_subscription(agnocast.Message, "/py/not_a_type", 1, print)


def test_callback_groups_have_the_names_ros_2_users_know():
    assert agnocast.MutuallyExclusiveCallbackGroup().type == agnocast.CallbackGroupType.MutuallyExclusive
    assert agnocast.ReentrantCallbackGroup().type == agnocast.CallbackGroupType.Reentrant
    node = agnocast.Node("py_groups_native")
    assert node.default_callback_group.type == agnocast.CallbackGroupType.MutuallyExclusive
    assert node.create_callback_group(agnocast.CallbackGroupType.Reentrant).type == \
        agnocast.CallbackGroupType.Reentrant


def test_service_types_are_classes_holding_their_two_message_classes():
    for srv, name in [(Empty, "std_srvs/srv/Empty"), (Trigger, "std_srvs/srv/Trigger"),
                      (SetBool, "std_srvs/srv/SetBool"),
                      (AddTwoInts, "example_interfaces/srv/AddTwoInts"),
                      (Rate, "wheel_msgs/srv/Rate")]:
        assert isinstance(srv, type) and issubclass(srv, agnocast.ServiceType)
        assert srv.type_name == name
        assert srv.__name__ == name.rsplit("/", 1)[1]
        assert srv.__module__ == "agnocast.srv." + name.split("/")[0]
        assert issubclass(srv.Request, agnocast.Message)
        assert srv.Request.type_name == name + "_Request"
        assert srv.Response.type_name == name + "_Response"
        assert srv.Request.__name__ == srv.__name__ + "_Request"
    assert SetBool.Request.fields == ["data"]
    assert SetBool.Response.fields == ["success", "message"]
    assert Empty.Request.fields == ["structure_needs_at_least_one_member"]
    assert AddTwoInts.Request.fields == ["a", "b"] and AddTwoInts.Response.fields == ["sum"]
    assert Rate.Request.definition.startswith("# Rates a wheel from the speeds it reported.\n")
    assert repr(SetBool) == "<agnocast service class std_srvs/srv/SetBool>"


def test_a_service_type_makes_no_instance_and_only_it_makes_a_client():
    with pytest.raises(TypeError, match="is a service type"):
        SetBool()
    node = agnocast.Node("py_not_a_service")
    with pytest.raises(TypeError, match="not a service type"):
        node.create_client(SetBool.Request, "/py/not_a_service")
    with pytest.raises(TypeError, match="not a service type"):
        node.create_service(String, "/py/not_a_service", print)
