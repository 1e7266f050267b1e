// Must not compile: a subscription callback that takes the message by
// non-const reference; the error names the accepted forms.
// expect: a subscription callback must take `const agnocast::ipc_shared_ptr<const Msg>&` or `const Msg&`
// expect: optionally followed by `const agnocast::MessageInfo&`
#include <agnocast/agnocast.hpp>

struct Reading {
  double value;
};

int main() {
  agnocast::Node node{"mutable"};
  auto subscription = node.create_subscription<Reading>("/readings", agnocast::QoS{1},
                                                        [](Reading& reading) { reading.value = 0; });
}
