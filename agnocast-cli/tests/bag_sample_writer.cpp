// Writes an MCAP file as bag record does (schema-driven CDR and .msg text,
// rosbag2's channel metadata) from messages built in a pool here, and a JSON
// file of the values each message holds, rendered from the schema, and of the
// .msg files a user type's definition must hold word for word. Readers
// written elsewhere (tests/mcap-readers) check the one against the other.
//   agnocast_bag_sample_writer OUT.mcap EXPECTED.json zstd|lz4|none
#include <agnocast/agnocast.hpp>
#include <agnocast/message_render.hpp>
#include <agnocast/schema_cdr.hpp>
#include <agnocast/schema_definition.hpp>
#include <algorithm>
#include <fstream>
#include <golden_msgs/msg/wheel.hpp>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sensor_msgs/msg/imu.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <sstream>

#include "agnocast/mcap/writer.hpp"
#include "bag/bag.hpp"
#include "bag/qos_profiles.hpp"
#include "kernel/runtime.hpp"

namespace bag_sample {

struct Text {
  agnocast::string data;
  std::int32_t count;
  bool flag;
  agnocast::vector<double> values;
  std::array<std::uint16_t, 3> triple;
  std::int64_t big;
};

}  // namespace bag_sample

AGNOCAST_MESSAGE(bag_sample::Text, "bag_sample/msg/Text", data, count, flag, values, triple, big);

namespace {

template <class T>
T* in_pool() {
  void* memory = agnocast::detail::allocate_message(sizeof(T), alignof(T), nullptr);
  return new (memory) T();
}

class SampleFile {
 public:
  SampleFile(const std::string& path, agnocast::mcap::Compression compression)
      : writer_(path, {.profile = "ros2",
                       .library = "agnocast_bag_sample_writer",
                       .compression = compression,
                       .chunk_size = 64 * 1024}) {}

  template <class T>
  std::uint16_t topic(const std::string& name) {
    const agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<T>());
    const std::string text = agnocast::ros2msg_definition(schema);
    const auto schema_id =
        writer_.add_schema(schema.types[0].name, "ros2msg", {text.begin(), text.end()});
    return writer_.add_channel(
        schema_id, name, "cdr",
        {{"offered_qos_profiles", agnocast::cli::offered_qos_profiles({{10, false}})}});
  }

  template <class T>
  void message(std::uint16_t channel, const std::string& topic, const T& value) {
    const agnocast::Schema schema = agnocast::parse_schema(agnocast::schema_of<T>());
    std::vector<std::uint8_t> bytes;
    agnocast::serialize_with_schema(
        &value, schema, bytes, {.readable = agnocast::detail::Runtime::get().pool_holding(&value)});
    time_ += 1'000'000;
    writer_.write_message(channel, time_, time_ - 500, bytes);
    expected_.push_back(
        {{"topic", topic},
         {"log_time", std::to_string(time_)},
         {"value", nlohmann::json::parse(agnocast::render_message_json(&value, schema))}});
  }

  // The schema of `type_name` must be these texts: its own, then each type it uses.
  void expect_definition(const std::string& type_name, const std::string& own,
                         const std::map<std::string, std::string>& uses) {
    definitions_.push_back({{"schema", type_name}, {"own", own}, {"uses", uses}});
  }

  void close(const std::string& expected_path) {
    writer_.close();
    const nlohmann::json expected{{"messages", expected_}, {"definitions", definitions_}};
    std::ofstream(expected_path) << expected.dump(1) << '\n';
  }

 private:
  agnocast::mcap::Writer writer_;
  std::uint64_t time_ = 1'700'000'000'000'000'000;
  nlohmann::json expected_ = nlohmann::json::array();
  nlohmann::json definitions_ = nlohmann::json::array();
};

std::string golden_msg_file(const char* name) {
  std::ifstream file(std::string(GOLDEN_MSGS_DIR) + "/" + name + ".msg");
  std::stringstream text;
  text << file.rdbuf();
  if (text.str().empty()) throw std::runtime_error(std::string("cannot read ") + name + ".msg");
  return text.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: agnocast_bag_sample_writer OUT.mcap EXPECTED.json zstd|lz4|none\n";
    return 2;
  }
  const std::string compression_name = argv[3];
  const auto compression = compression_name == "zstd"  ? agnocast::mcap::Compression::Zstd
                           : compression_name == "lz4" ? agnocast::mcap::Compression::Lz4
                                                       : agnocast::mcap::Compression::None;
  static constexpr std::size_t pool_size = 64 << 20;
  auto* region = new (std::align_val_t{4096}) std::byte[pool_size];
  agnocast::detail::Runtime::install_for_testing(region, pool_size);

  SampleFile file(argv[1], compression);
  const auto points = file.topic<sensor_msgs::msg::PointCloud2>("/points");
  const auto chatter = file.topic<bag_sample::Text>("/chatter");
  const auto imu = file.topic<sensor_msgs::msg::Imu>("/imu");
  // A user's type with constants, comments, bounds and a same-package type:
  // recorded, its definition is its .msg files as they are, as rosbag2 writes it.
  const auto wheels = file.topic<golden_msgs::msg::Wheel>("/wheel");
  file.expect_definition("golden_msgs/msg/Wheel", golden_msg_file("Wheel"),
                         {{"golden_msgs/Tire", golden_msg_file("Tire")}});
  for (int i = 0; i < 5; ++i) {
    auto* cloud = in_pool<sensor_msgs::msg::PointCloud2>();
    cloud->header.stamp.sec = 1700000000 + i;
    cloud->header.stamp.nanosec = 1000u * static_cast<std::uint32_t>(i);
    cloud->header.frame_id = "a_frame_name_longer_than_any_small_string_buffer";
    cloud->height = 1;
    cloud->width = 5000;
    for (const char* name : {"x", "y", "z", "intensity"}) {
      sensor_msgs::msg::PointField field;
      field.name = name;
      field.offset = static_cast<std::uint32_t>(4 * cloud->fields.size());
      field.datatype = sensor_msgs::msg::PointField::FLOAT32;
      field.count = 1;
      cloud->fields.push_back(field);
    }
    cloud->point_step = 16;
    cloud->row_step = 16 * cloud->width;
    cloud->data.resize(cloud->row_step);
    for (std::size_t b = 0; b < cloud->data.size(); ++b) {
      cloud->data[b] = static_cast<std::uint8_t>(b * 13 + static_cast<std::size_t>(i));
    }
    cloud->is_dense = i % 2 == 0;
    file.message(points, "/points", *cloud);

    auto* text = in_pool<bag_sample::Text>();
    text->data = "hello " + std::to_string(i) + (i == 3 ? std::string(40, 'x') : "");
    text->count = -7 * i;
    text->flag = i % 2 == 1;
    for (int v = 0; v < i; ++v) text->values.push_back(0.5 * v - 1.25);
    text->triple = {static_cast<std::uint16_t>(i), 65535, 7};
    text->big = -1234567890123LL * i;
    file.message(chatter, "/chatter", *text);

    auto* reading = in_pool<sensor_msgs::msg::Imu>();
    reading->header.frame_id = "imu";
    reading->orientation.w = 1.0;
    reading->angular_velocity.z = 0.25 * i;
    reading->linear_acceleration.x = -9.75;
    reading->orientation_covariance[0] = 0.5;
    reading->orientation_covariance[8] = 2.0;
    file.message(imu, "/imu", *reading);

    auto* wheel = in_pool<golden_msgs::msg::Wheel>();
    wheel->header.frame_id = "wheel_" + std::to_string(i);
    wheel->tire.pressure_kpa = static_cast<std::uint16_t>(200 + i);
    wheel->tire.brand = "a brand name longer than a small string buffer";
    wheel->radius = 0.25 + i;
    wheel->speeds.assign(static_cast<std::size_t>(i), 1.5F);
    // Appended, not "t" + to_string(i): GCC 12 at -O3 warns falsely (-Wrestrict) on that form.
    const std::string tag = std::string("t").append(std::to_string(i));
    wheel->tags.push_back(tag.c_str());
    wheel->flags = {1, 0, static_cast<std::uint8_t>(i % 2)};
    wheel->enabled = i % 2 == 0;
    wheel->spares[1].brand = "spare";
    if (i > 0) wheel->axes.resize(static_cast<std::size_t>(std::min(i, 3)));
    wheel->status = golden_msgs::msg::Wheel::MODE_DRIVE;
    wheel->odometer = 1'000'000'000ULL * static_cast<std::uint64_t>(i);
    file.message(wheels, "/wheel", *wheel);
  }
  file.close(argv[2]);
  return 0;
}
