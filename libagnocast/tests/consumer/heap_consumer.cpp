// A message type with std containers, its publisher linked with agnocast::heaphook.
#include <agnocast/agnocast.hpp>
#include <agnocast/heap_scope.hpp>
#include <cstdio>
#include <string>
#include <vector>

struct Labels {
  std::vector<std::string> labels;
};
AGNOCAST_HEAP_MESSAGE(Labels, "consumer/msg/Labels", labels);

int main() {
  auto publish_one = [](agnocast::Node& node) {
    auto publisher = node.create_publisher<Labels>("/labels", agnocast::QoS{1});
    auto message = publisher->borrow_loaned_message();
    message->labels.emplace_back("in the pool");
    publisher->publish(std::move(message));
  };
  (void)publish_one;
  std::printf("heaphook %s\n", agnocast::heap_scope::hook_active() ? "active" : "inactive");
}
