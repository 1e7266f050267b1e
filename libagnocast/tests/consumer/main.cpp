// Compiles against every public header and links; runs without the module.
#include <agnocast/agnocast.hpp>
#include <agnocast/inspect.hpp>
#include <agnocast/supervise.hpp>
#include <cstdio>

struct Reading {
  double value = 0;
  agnocast::vector<agnocast::string> labels;
};
AGNOCAST_MESSAGE(Reading, "consumer/msg/Reading", value, labels);

int main() {
  // Instantiating the templates is the point: no device is needed to compile them.
  auto publish_one = [](agnocast::Node& node) {
    auto publisher = node.create_publisher<Reading>("/consumer", agnocast::QoS{1});
    auto message = publisher->borrow_loaned_message();
    message->labels.emplace_back("zero-copy");
    publisher->publish(std::move(message));
    auto subscription = node.create_subscription<Reading>(
        "/consumer", agnocast::QoS{1}.transient_local(),
        [](const agnocast::ipc_shared_ptr<const Reading>& reading) { (void)reading->value; });
    agnocast::MultiThreadedExecutor executor;
    executor.add_node(node);
    executor.spin_some();
  };
  (void)publish_one;
  if (!agnocast::is_valid_topic_name("/consumer")) return 1;
  if (agnocast::queue_name("/a/b", 1) != "/a_b@1") return 1;
  std::printf("agnocast %s\n", std::string(agnocast::library_version_string).c_str());
  return 0;
}
