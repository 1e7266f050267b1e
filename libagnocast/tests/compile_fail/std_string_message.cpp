// Must not compile: std::string points into the publisher's heap, which no
// subscriber can read. The compiler's message must name the rule and the fix.
#include <agnocast/agnocast.hpp>
#include <string>

struct Greeting {
  std::string text;
};

void publish(agnocast::Node& node) {
  (void)node.create_publisher<Greeting>("/greeting", agnocast::QoS{1});
}
