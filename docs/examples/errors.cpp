// What can go wrong, what the library throws, and where its warnings go.
#include <agnocast/agnocast.hpp>
#include <cstdio>
#include <new>
#include <stdexcept>

#include "robot_messages.hpp"

int main() {
  // The library never prints; hand its warnings to your logger.
  agnocast::set_log_handler([](agnocast::LogLevel level, std::string_view message) {
    if (level >= agnocast::LogLevel::warning) {
      std::fprintf(stderr, "agnocast: %.*s\n", static_cast<int>(message.size()), message.data());
    }
  });
  try {
    agnocast::Node node{"errors"};
    auto publisher = node.create_publisher<robot::Scan>("/scan", agnocast::QoS{10});
    auto scan = publisher->borrow_loaned_message();
    scan->ranges.resize(1 << 20);
    publisher->publish(std::move(scan));
  } catch (const agnocast::ModuleNotLoaded& error) {
    std::fprintf(stderr, "%s\n", error.what());  // says: systemctl start agnocastd
    return 2;
  } catch (const agnocast::TypeMismatch& error) {
    std::fprintf(stderr, "%s\n", error.what());  // /scan carries another type
    return 3;
  } catch (const agnocast::AccessDenied& error) {
    std::fprintf(stderr, "%s\n", error.what());  // the topic policy refuses this user
    return 4;
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "%s\n", error.what());  // a bad topic name or depth
    return 5;
  } catch (const std::bad_alloc& error) {
    std::fprintf(stderr, "%s\n", error.what());  // the pool is full: names pool_size
    return 6;
  } catch (const agnocast::Error& error) {
    std::fprintf(stderr, "%s\n", error.what());  // anything else the module or a queue refused
    return 7;
  }
}
