// Compiles against every public header and links; runs without the module.
#include <agnocast/agnocast.hpp>
#include <agnocast/inspect.hpp>
#include <agnocast/message_render.hpp>
#include <agnocast/supervise.hpp>
#include <consumer_msgs/msg/reading.hpp>
#include <cstdio>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <visualization_msgs/msg/marker_array.hpp>

struct Sample {
  double value = 0;
  agnocast::vector<agnocast::string> labels;
};
AGNOCAST_MESSAGE(Sample, "consumer/msg/Sample", value, labels);

int main() {
  // Instantiating the templates is the point: no device is needed to compile them.
  auto publish_one = [](agnocast::Node& node) {
    auto publisher =
        node.create_publisher<consumer_msgs::msg::Reading>("/consumer", agnocast::QoS{1});
    auto message = publisher->borrow_loaned_message();
    message->labels.emplace_back("zero-copy");
    publisher->publish(std::move(message));
    auto subscription = node.create_subscription<Sample>(
        "/consumer", agnocast::QoS{1}.transient_local(),
        [](const agnocast::ipc_shared_ptr<const Sample>& sample) { (void)sample->value; });
    auto poller =
        node.create_polling_subscriber<sensor_msgs::msg::PointCloud2>("/points", agnocast::QoS{1});
    agnocast::MultiThreadedExecutor executor;
    executor.add_node(node);
    executor.spin_some();
  };
  (void)publish_one;
  if (!agnocast::is_valid_topic_name("/consumer")) return 1;
  if (agnocast::queue_name("/a/b", 1) != "/a_b@1") return 1;
  // The generated traits and schema of a type nesting the installed standard set.
  const agnocast::Schema schema =
      agnocast::parse_schema(agnocast::schema_of<consumer_msgs::msg::Reading>());
  if (schema.types[0].name != "consumer_msgs/msg/Reading" || schema.types.size() != 4) return 1;
  if (agnocast::message_traits<visualization_msgs::msg::MarkerArray>::type_name !=
      "visualization_msgs/msg/MarkerArray") {
    return 1;
  }
  std::printf("agnocast %s\n", std::string(agnocast::library_version_string).c_str());
  return 0;
}
