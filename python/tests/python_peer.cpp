// The C++ side of the Python interop tests: publishes or subscribes one typed
// topic, serves or calls one service, and prints what it sent or received,
// one line per message, so the Python test can compare (contents, and the
// pool address of an array or a message).
//
// usage: python_peer pub|sub string|cloud|wheel TOPIC COUNT [SIZE]
//        python_peer hostile cloud TOPIC
//        python_peer serve add SERVICE
//        python_peer call add SERVICE A B
//        python_peer hostile-client rate SERVICE
//   pub: waits for a subscriber, then publishes COUNT messages 100 ms apart
//        (cloud: SIZE bytes of data, byte i = (i + seq) % 251), then waits
//        for the end of stdin
//   sub: prints each message until COUNT arrived, exits 0 (1 after 60 s)
//   hostile: publishes one cloud per way its containers can lie (see
//        hostile_clouds), printing the fault's name, then waits for stdin
//   serve: an example_interfaces/srv/AddTwoInts server; prints "ready", then
//        per request "add A B REQUEST_ADDRESS RESPONSE_ADDRESS", until stdin ends
//   call: an AddTwoInts client; prints "sum S RESPONSE_ADDRESS" (exit 1 when
//        no answer came within 30 s)
//   hostile-client: a wheel_msgs/srv/Rate client whose first requests lie
//        (see hostile_rates); prints the answer to the last, honest one
#include <agnocast/agnocast.hpp>
#include <agnocast/schema_layout.hpp>
#include <chrono>
#include <future>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <example_interfaces/srv/add_two_ints.hpp>
#include <geometry_msgs/msg/vector3.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <std_msgs/msg/string.hpp>
#include <string>
#include <thread>
#include <wheel_msgs/msg/wheel.hpp>
#include <wheel_msgs/srv/rate.hpp>

namespace {

using namespace std::chrono_literals;

void fill(std_msgs::msg::String& m, int seq) {
  m.data = ("hello from C++ " + std::to_string(seq)).c_str();
}
void fill(sensor_msgs::msg::PointCloud2& m, int seq, std::size_t size) {
  m.header.frame_id = "lidar";
  m.header.stamp.sec = seq;
  m.height = 1;
  m.width = static_cast<std::uint32_t>(size / 16);
  m.point_step = 16;
  m.row_step = m.width * 16;
  // Built aside and appended: assigning to a resized element's string draws
  // a false -Wrestrict from GCC 12 at -O3.
  sensor_msgs::msg::PointField x;
  x.name = "x";
  x.offset = 0;
  x.datatype = 7;
  x.count = 1;
  m.fields.push_back(x);
  m.data.resize(size);
  for (std::size_t i = 0; i < size; ++i) m.data[i] = static_cast<std::uint8_t>((i + seq) % 251);
}
void fill(wheel_msgs::msg::Wheel& m, int seq) {
  m.header.frame_id = "wheel";
  m.name = "front left";
  m.speeds.resize(3);
  for (int i = 0; i < 3; ++i) m.speeds[i] = seq + i * 0.5;
  for (int i = 0; i < 4; ++i) m.torque[i] = -seq * 10 - i;
  m.forces.resize(2);
  m.forces[1].z = 9.81 * seq;
  m.labels.emplace_back("a");
  m.labels.emplace_back("long label beyond any small-string buffer");
}

void print(const std_msgs::msg::String& m) { std::printf("string %s\n", m.data.c_str()); }
void print(const sensor_msgs::msg::PointCloud2& m) {
  unsigned long long sum = 0;
  for (const auto byte : m.data) sum += byte;
  std::printf("cloud %s %d %u %zu %llu %s %u %p\n", m.header.frame_id.c_str(), m.header.stamp.sec,
              m.width, m.data.size(), sum, m.fields.empty() ? "-" : m.fields[0].name.c_str(),
              m.fields.empty() ? 0u : m.fields[0].offset, static_cast<const void*>(m.data.data()));
}
void print(const wheel_msgs::msg::Wheel& m) {
  std::printf("wheel %s %s", m.header.frame_id.c_str(), m.name.c_str());
  for (const double s : m.speeds) std::printf(" %g", s);
  std::printf(" |");
  for (const int t : m.torque) std::printf(" %d", t);
  std::printf(" | %zu", m.forces.size());
  for (const auto& f : m.forces) std::printf(" %g", f.z);
  std::printf(" |");
  for (const auto& l : m.labels) std::printf(" [%s]", l.c_str());
  std::printf("\n");
}

template <class T>
int run(bool publish, const std::string& topic, int count, std::size_t size) {
  agnocast::Node node{"python_peer"};
  if (publish) {
    auto pub = node.create_publisher<T>(topic, agnocast::QoS{10});
    if (!pub->wait_for_subscribers(1, 60s)) return 1;
    for (int seq = 1; seq <= count; ++seq) {
      auto m = pub->borrow_loaned_message();
      if constexpr (std::is_same_v<T, sensor_msgs::msg::PointCloud2>) {
        fill(*m, seq, size);
      } else {
        fill(*m, seq);
      }
      print(*m);
      std::fflush(stdout);
      pub->publish(std::move(m));
      std::this_thread::sleep_for(100ms);
    }
    // Stay until stdin closes: the test decides when it is done with the messages.
    while (std::getchar() != EOF) {
    }
    return 0;
  }
  int received = 0;
  agnocast::SingleThreadedExecutor exec;
  auto sub = node.create_subscription<T>(topic, agnocast::QoS{10}, [&](const T& m) {
    print(m);
    std::fflush(stdout);
    if (++received >= count) exec.cancel();
  });
  std::printf("ready\n");
  std::fflush(stdout);
  exec.add_node(node);
  std::thread watchdog([&] {
    for (int i = 0; i < 600 && received < count; ++i) std::this_thread::sleep_for(100ms);
    exec.cancel();
  });
  exec.spin();
  watchdog.join();
  return received >= count ? 0 : 1;
}

// Rewrites the words of a vector or string in place, as a hostile publisher can.
void write_word(void* container, std::uint8_t offset, std::uintptr_t value) {
  std::memcpy(static_cast<std::byte*>(container) + offset, &value, sizeof(value));
}
std::uintptr_t read_word(const void* container, std::uint8_t offset) {
  std::uintptr_t value;
  std::memcpy(&value, static_cast<const std::byte*>(container) + offset, sizeof(value));
  return value;
}

// A cloud whose containers lie, one way per message: where a subscriber must
// refuse to read, naming the field. The messages are never destroyed (the
// process ends with _Exit), since their destructors would free what the words
// now point to.
int hostile_clouds(const std::string& topic) {
  const agnocast::ContainerLayout& layout = agnocast::native_container_layout();
  constexpr std::uintptr_t unmapped = 0x10000;  // below any pool, mapped by no one
  agnocast::Node node{"python_peer_hostile"};
  auto pub = node.create_publisher<sensor_msgs::msg::PointCloud2>(topic, agnocast::QoS{10});
  if (!pub->wait_for_subscribers(1, 60s)) return 1;
  const char* faults[] = {"data_outside", "data_huge", "fields_misaligned", "frame_id_outside"};
  for (const char* fault : faults) {
    auto m = pub->borrow_loaned_message();
    fill(*m, 1, 64);
    const std::string name = fault;
    if (name == "data_outside") {
      write_word(&m->data, layout.vector_begin_offset, unmapped);
      write_word(&m->data, layout.vector_end_offset, unmapped + 64);
    } else if (name == "data_huge") {
      const std::uintptr_t begin = read_word(&m->data, layout.vector_begin_offset);
      write_word(&m->data, layout.vector_end_offset, begin + (std::uintptr_t{1} << 40));
    } else if (name == "fields_misaligned") {
      write_word(&m->fields, layout.vector_begin_offset,
                 read_word(&m->fields, layout.vector_begin_offset) + 1);
      write_word(&m->fields, layout.vector_end_offset,
                 read_word(&m->fields, layout.vector_end_offset) + 1);
    } else {
      write_word(&m->header.frame_id, layout.string_data_offset, unmapped);
    }
    std::printf("%s\n", fault);
    std::fflush(stdout);
    pub->publish(std::move(m));
    std::this_thread::sleep_for(100ms);
  }
  while (std::getchar() != EOF) {
  }
  std::_Exit(0);
}

using AddTwoInts = example_interfaces::srv::AddTwoInts;
using Rate = wheel_msgs::srv::Rate;

int serve_add(const std::string& service) {
  agnocast::Node node{"python_peer_server"};
  auto server = node.create_service<AddTwoInts>(
      service, [](const agnocast::ipc_shared_ptr<const AddTwoInts::Request>& request,
                  agnocast::ipc_shared_ptr<AddTwoInts::Response>& response) {
        response->sum = request->a + request->b;
        std::printf("add %lld %lld %p %p\n", static_cast<long long>(request->a),
                    static_cast<long long>(request->b), static_cast<const void*>(request.get()),
                    static_cast<const void*>(response.get()));
        std::fflush(stdout);
      });
  agnocast::SingleThreadedExecutor exec;
  exec.add_node(node);
  std::thread spinner([&] { exec.spin(); });
  std::printf("ready\n");
  std::fflush(stdout);
  while (std::getchar() != EOF) {
  }
  exec.cancel();
  spinner.join();
  return 0;
}

int call_add(const std::string& service, std::int64_t a, std::int64_t b) {
  agnocast::Node node{"python_peer_client"};
  auto client = node.create_client<AddTwoInts>(service);
  if (!client->wait_for_service(30s)) return 1;
  auto request = client->borrow_loaned_request();
  request->a = a;
  request->b = b;
  auto future = client->async_send_request(std::move(request));
  agnocast::SingleThreadedExecutor exec;
  exec.add_node(node);
  for (int i = 0; i < 300 && future.wait_for(0s) != std::future_status::ready; ++i) {
    exec.spin_once(100ms);
  }
  if (future.wait_for(0s) != std::future_status::ready) return 1;
  const auto& response = future.get();
  std::printf("sum %lld %p\n", static_cast<long long>(response->sum),
              static_cast<const void*>(response.get()));
  return 0;
}

// Requests whose containers lie, one way each, then an honest one, all
// borrowed before any is sent: a lying request is never destroyed (its
// destructor would free what its words now point to), as no borrow comes
// after it to free what was reclaimed, and the process ends with _Exit.
int hostile_rates(const std::string& service) {
  const agnocast::ContainerLayout& layout = agnocast::native_container_layout();
  constexpr std::uintptr_t unmapped = 0x10000;  // below any pool, mapped by no one
  agnocast::Node node{"python_peer_hostile_client"};
  auto client = node.create_client<Rate>(service);
  if (!client->wait_for_service(30s)) return 1;
  auto speeds_outside = client->borrow_loaned_request();
  auto name_outside = client->borrow_loaned_request();
  auto honest = client->borrow_loaned_request();
  for (auto* request : {speeds_outside.get(), name_outside.get(), honest.get()}) {
    request->name = "front left, named beyond any small-string buffer";
    request->speeds = {1.0, 2.0, 4.5};
  }
  write_word(&speeds_outside->speeds, layout.vector_begin_offset, unmapped);
  write_word(&speeds_outside->speeds, layout.vector_end_offset, unmapped + 24);
  write_word(&name_outside->name, layout.string_data_offset, unmapped);
  client->async_send_request(std::move(speeds_outside));
  client->async_send_request(std::move(name_outside));
  auto future = client->async_send_request(std::move(honest));
  agnocast::SingleThreadedExecutor exec;
  exec.add_node(node);
  for (int i = 0; i < 300 && future.wait_for(0s) != std::future_status::ready; ++i) {
    exec.spin_once(100ms);
  }
  if (future.wait_for(0s) != std::future_status::ready) std::_Exit(1);
  std::printf("answered %g %s\n", future.get()->mean, future.get()->verdict.c_str());
  std::fflush(stdout);
  std::_Exit(0);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "hostile" && std::string(argv[2]) == "cloud") {
    return hostile_clouds(argv[3]);
  }
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (argc == 4 && mode == "serve" && std::string(argv[2]) == "add") return serve_add(argv[3]);
    if (argc == 6 && mode == "call" && std::string(argv[2]) == "add") {
      return call_add(argv[3], std::atoll(argv[4]), std::atoll(argv[5]));
    }
    if (argc == 4 && mode == "hostile-client" && std::string(argv[2]) == "rate") {
      return hostile_rates(argv[3]);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "python_peer: %s\n", e.what());
    return 1;
  }
  if (argc < 5) {
    std::fprintf(stderr,
                 "usage: python_peer pub|sub string|cloud|wheel TOPIC COUNT [SIZE]\n"
                 "       python_peer hostile cloud TOPIC\n"
                 "       python_peer serve add SERVICE\n"
                 "       python_peer call add SERVICE A B\n"
                 "       python_peer hostile-client rate SERVICE\n");
    return 2;
  }
  const bool publish = std::string(argv[1]) == "pub";
  const std::string type = argv[2];
  const int count = std::atoi(argv[4]);
  const std::size_t size = argc > 5 ? std::strtoull(argv[5], nullptr, 10) : 1024;
  try {
    if (type == "string") return run<std_msgs::msg::String>(publish, argv[3], count, size);
    if (type == "cloud") return run<sensor_msgs::msg::PointCloud2>(publish, argv[3], count, size);
    if (type == "wheel") return run<wheel_msgs::msg::Wheel>(publish, argv[3], count, size);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "python_peer: %s\n", e.what());
    return 1;
  }
  return 2;
}
