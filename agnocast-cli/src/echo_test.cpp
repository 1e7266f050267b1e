// topic echo end to end against a fake system whose messages are canned bytes
// laid out as a publisher in another process would leave them in its pool.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <sstream>

#include "agnocast/message.hpp"
#include "cli.hpp"
#include "fake_source.hpp"

namespace echo_test {

struct Point {
  double x;
  double y;
};

struct Reading {
  std::int32_t id;
  agnocast::string label;
  Point origin;
  agnocast::vector<float> values;
};

}  // namespace echo_test

AGNOCAST_MESSAGE(echo_test::Point, "echo_test/msg/Point", x, y);
AGNOCAST_MESSAGE(echo_test::Reading, "echo_test/msg/Reading", id, label, origin, values);

namespace agnocast::cli {
namespace {

// A publisher's pool holding Reading messages, written byte by byte from the
// schema: the fake's subscriber takes them from here.
class CannedPool {
 public:
  CannedPool() : schema_(parse_schema(schema_of<echo_test::Reading>())) {}

  std::span<const std::byte> range() const { return bytes_; }
  const Schema& schema() const { return schema_; }

  // A Reading at a fresh place in the pool.
  std::byte* reading(std::int32_t id, std::string_view label, double x, double y,
                     std::span<const float> values) {
    const SchemaType& type = schema_.types[0];
    std::byte* message = place(type.size, type.align);
    write(message + offset(type, "id"), id);
    write_string(message + offset(type, "label"), label);
    const SchemaType& point = schema_.types[1];
    write(message + offset(type, "origin") + offset(point, "x"), x);
    write(message + offset(type, "origin") + offset(point, "y"), y);
    std::byte* elements = place(values.size_bytes(), alignof(float));
    if (!values.empty())
      std::memcpy(elements, values.data(), values.size_bytes());  // data() may be null
    write_vector(message + offset(type, "values"), elements, values.size_bytes());
    return message;
  }

  static std::uint32_t offset(const SchemaType& type, std::string_view field) {
    for (const SchemaField& f : type.fields) {
      if (f.name == field) return f.offset;
    }
    throw std::logic_error("no field " + std::string(field));
  }

  template <class T>
  static void write(std::byte* at, T value) {
    std::memcpy(at, &value, sizeof(T));
  }

  void write_string(std::byte* at, std::string_view text) {
    std::byte* data = place(text.size(), 1);
    std::memcpy(data, text.data(), text.size());
    write(at + schema_.containers.string_data_offset, data);
    write(at + schema_.containers.string_length_offset, text.size());
  }

  void write_vector(std::byte* at, std::byte* begin, std::size_t bytes) {
    write(at + schema_.containers.vector_begin_offset, begin);
    write(at + schema_.containers.vector_end_offset, begin + bytes);
  }

 private:
  std::byte* place(std::size_t size, std::size_t align) {
    used_ = (used_ + align - 1) / align * align;
    std::byte* at = bytes_.data() + used_;
    used_ += size;
    if (used_ > bytes_.size()) throw std::logic_error("canned pool full");
    return at;
  }

  alignas(64) std::array<std::byte, 4096> bytes_{};
  std::size_t used_ = 0;
  Schema schema_;
};

struct Outcome {
  int code;
  std::string out;
  std::string err;
};

class TopicEcho : public ::testing::Test {
 protected:
  void SetUp() override {
    source_ = healthy_system();
    const std::array<float, 3> values{0.5F, -1.0F, 2.25F};
    add(pool_.reading(7, "first", 1.5, -2.0, values));
    add(pool_.reading(8, "second \"one\"", 0.0, 3.0, std::span<const float>()));
  }

  void add(const void* message) {
    FakeStream& stream = source_.streams["/chatter"];
    stream.schema.assign(schema_of<echo_test::Reading>().begin(),
                         schema_of<echo_test::Reading>().end());
    stream.messages.emplace_back(message, pool_.range());
  }

  Outcome run(std::vector<const char*> args) {
    args.insert(args.begin(), {"agnocast-cli", "topic", "echo"});
    std::ostringstream out, err;
    const int code = run_cli(static_cast<int>(args.size()), args.data(), source_, out, err);
    return {code, out.str(), err.str()};
  }

  FakeSource source_;
  CannedPool pool_;
};

TEST_F(TopicEcho, TextIsOneYamlLikeDocumentPerMessage) {
  const Outcome r = run({"/chatter", "--count", "2"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out,
            "id: 7\n"
            "label: \"first\"\n"
            "origin:\n"
            "  x: 1.5\n"
            "  y: -2\n"
            "values: [0.5, -1, 2.25]\n"
            "---\n"
            "id: 8\n"
            "label: \"second \\\"one\\\"\"\n"
            "origin:\n"
            "  x: 0\n"
            "  y: 3\n"
            "values: []\n"
            "---\n");
  EXPECT_EQ(r.err, "");
}

TEST_F(TopicEcho, JsonIsOneObjectPerLine) {
  const Outcome r = run({"/chatter", "--count", "2", "--json"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, R"({"id":7,"label":"first","origin":{"x":1.5,"y":-2},"values":[0.5,-1,2.25]})"
                   "\n"
                   R"({"id":8,"label":"second \"one\"","origin":{"x":0,"y":3},"values":[]})"
                   "\n");
}

TEST_F(TopicEcho, NoArraysShowsLengths) {
  const Outcome text = run({"/chatter", "--count", "1", "--no-arrays"});
  EXPECT_NE(text.out.find("values: <3 elements>\n"), std::string::npos) << text.out;
  const Outcome json = run({"/chatter", "--count", "1", "--no-arrays", "--json"});
  EXPECT_EQ(json.out, R"({"id":7,"label":"first","origin":{"x":1.5,"y":-2},"values":{"length":3}})"
                      "\n");
}

TEST_F(TopicEcho, CountStopsBeforeLaterMessages) {
  const Outcome r = run({"/chatter", "--count", "1", "--json"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1);
}

TEST_F(TopicEcho, WaitsForMessagesThatArriveLater) {
  source_.streams["/chatter"].messages.clear();
  int sleeps = 0;
  source_.on_sleep = [&](FakeSource&) {
    if (++sleeps == 50) add(pool_.reading(9, "late", 0, 0, std::span<const float>()));
  };
  const Outcome r = run({"/chatter", "--count", "1", "--timeout", "5", "--json"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("id"), 9);
  EXPECT_EQ(sleeps, 50);
}

TEST_F(TopicEcho, TimeoutWithFewerThanCountExitsOne) {
  const Outcome r = run({"/chatter", "--count", "3", "--timeout", "0.5"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("id: 8\n"), std::string::npos);  // what arrived is printed
  EXPECT_NE(r.err.find("2 messages on topic '/chatter' within 0.5 s, wanted 3"), std::string::npos)
      << r.err;
  EXPECT_GE(source_.clock, 100.5);
  EXPECT_LT(source_.clock, 100.6);
}

TEST_F(TopicEcho, TimeoutWithoutCountFailsOnlyWhenNothingArrived) {
  EXPECT_EQ(run({"/chatter", "--timeout", "1"}).code, 0);
  source_.streams["/chatter"].messages.clear();
  const Outcome r = run({"/chatter", "--timeout", "1"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("0 messages on topic '/chatter' within 1 s, wanted at least 1"),
            std::string::npos)
      << r.err;
}

TEST_F(TopicEcho, RunsUntilASignal) {
  int sleeps = 0;
  source_.on_sleep = [&](FakeSource& source) { source.stop = ++sleeps == 1000; };
  const Outcome r = run({"/chatter", "--json"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 2);
  EXPECT_EQ(sleeps, 1000);
}

TEST_F(TopicEcho, TopicWithoutSchemaOrEndpointExitsOne) {
  source_.streams.clear();
  const Outcome no_schema = run({"/chatter"});
  EXPECT_EQ(no_schema.code, 1);
  EXPECT_NE(no_schema.err.find("/chatter has no schema"), std::string::npos) << no_schema.err;
  EXPECT_EQ(no_schema.out, "");
  const Outcome absent = run({"/absent", "--json"});
  EXPECT_EQ(absent.code, 1);
  EXPECT_EQ(nlohmann::json::parse(absent.out).at("exit_code"), 1);
}

TEST_F(TopicEcho, HostilePointersPrintMarkers) {
  std::byte* message = pool_.reading(10, "x", 0, 0, std::span<const float>());
  const SchemaType& type = pool_.schema().types[0];
  const std::size_t length_at =
      CannedPool::offset(type, "label") + pool_.schema().containers.string_length_offset;
  CannedPool::write(message + length_at, std::size_t{1} << 40);
  const std::size_t values = CannedPool::offset(type, "values");
  pool_.write_vector(message + values, message + 1, 4 * sizeof(float));  // misaligned
  source_.streams["/chatter"].messages.clear();
  add(message);
  const Outcome r = run({"/chatter", "--count", "1", "--json"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out, R"({"id":10,"label":{"invalid":"string outside the publisher's pool"},)"
                   R"("origin":{"x":0,"y":0},"values":{"invalid":"misaligned sequence"}})"
                   "\n");
}

TEST_F(TopicEcho, DefinitionPrintsTheTypesMsgTextsWithoutSubscribing) {
  const std::string separator(80, '=');
  const Outcome declared = run({"/chatter", "--definition"});
  EXPECT_EQ(declared.code, 0) << declared.err;
  // A type declared in C++ has no .msg text: its fields stand for it.
  EXPECT_EQ(declared.out, "int32 id\nstring label\necho_test/Point origin\nfloat32[] values\n" +
                              separator + "\nMSG: echo_test/Point\nfloat64 x\nfloat64 y\n");

  // A generated type's schema carries its .msg file, constants and comments too.
  TypeDescriptor point = message_traits<echo_test::Point>::descriptor;
  const std::string text = "# where\nint8 ORIGIN=0\nfloat64 x  # east\nfloat64 y\n";
  point.definition = text;
  const std::vector<std::uint8_t> blob = build_schema(point);
  TopicInfo topic;
  topic.name = "/point";
  source_.topics.push_back(topic);
  source_.streams["/point"].schema = blob;
  const Outcome generated = run({"/point", "--definition", "--json"});
  EXPECT_EQ(generated.code, 0) << generated.err;
  EXPECT_EQ(
      nlohmann::json::parse(generated.out),
      (nlohmann::json{{"topic", "/point"}, {"type", "echo_test/msg/Point"}, {"definition", text}}));
  EXPECT_TRUE(source_.streams["/point"].messages.empty());

  source_.streams.erase("/point");
  const Outcome none = run({"/point", "--definition"});
  EXPECT_EQ(none.code, 1);
  EXPECT_NE(none.err.find("/point has no schema"), std::string::npos) << none.err;
}

TEST_F(TopicEcho, UsageErrorsExitTwo) {
  EXPECT_EQ(run({}).code, 2);
  EXPECT_EQ(run({"/chatter", "--count", "0"}).code, 2);
  EXPECT_EQ(run({"/chatter", "--timeout", "-1"}).code, 2);
  EXPECT_EQ(run({"chatter with spaces"}).code, 2);
}

}  // namespace
}  // namespace agnocast::cli
