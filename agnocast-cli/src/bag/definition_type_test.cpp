#include "bag/definition_type.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "agnocast/schema.hpp"
#include "agnocast/schema_definition.hpp"
#include "cli.hpp"
#include "golden_msgs/msg/wheel.hpp"
#include "standard_types.hpp"

namespace agnocast::cli {
namespace {

// What bag record writes for a type: the .msg texts its schema carries.
std::string recorded_definition(const std::vector<std::uint8_t>& schema) {
  return ros2msg_definition(parse_schema(schema));
}

TEST(DefinitionType, EveryStandardTypeIsLaidOutAsItsGeneratedHeader) {
  int checked = 0;
  for (const auto& package : std::filesystem::directory_iterator(MESSAGES_DIR)) {
    const std::filesystem::path msg_dir = package.path() / "msg";
    if (!std::filesystem::is_directory(msg_dir)) continue;
    for (const auto& file : std::filesystem::directory_iterator(msg_dir)) {
      if (file.path().extension() != ".msg") continue;
      const std::string name =
          package.path().filename().string() + "/msg/" + file.path().stem().string();
      const detail::MessageType* compiled = standard_message_type(name);
      ASSERT_NE(compiled, nullptr) << name;
      const std::vector<std::uint8_t> schema(compiled->schema.begin(), compiled->schema.end());
      const DefinitionType derived = type_from_definition(name, recorded_definition(schema));
      EXPECT_EQ(derived.type_name, name);
      EXPECT_EQ(derived.type_hash, compiled->hash) << name;
      EXPECT_EQ(derived.schema, schema) << name;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(DefinitionType, AUserTypeWithConstantsBoundsAndNestingMatchesItsGeneratedHeader) {
  // golden_msgs/Wheel: constants, defaults, comments, a same-package type,
  // bounded strings and sequences, bool[], byte and char, arrays of
  // messages. The definition is its .msg files' own text, as rosbag2 writes it.
  std::map<std::string, std::string, std::less<>> texts;
  for (const char* name : {"Wheel", "Tire"}) {
    std::ifstream file(std::string(GOLDEN_MSGS_DIR) + "/" + name + ".msg");
    std::stringstream text;
    text << file.rdbuf();
    texts["golden_msgs/msg/" + std::string(name)] = text.str();
  }
  const auto schema = schema_of<golden_msgs::msg::Wheel>();
  const std::string definition = ros2msg_definition(parse_schema(schema));
  ASSERT_EQ(definition.rfind(texts["golden_msgs/msg/Wheel"], 0), 0U) << definition;
  ASSERT_NE(definition.find("\nMSG: golden_msgs/Tire\n" + texts["golden_msgs/msg/Tire"]),
            std::string::npos)
      << definition;
  ASSERT_NE(definition.find("bool[] flags"), std::string::npos) << definition;
  ASSERT_NE(definition.find("uint8 MODE_DRIVE=1"), std::string::npos) << definition;
  const DefinitionType derived = type_from_definition("golden_msgs/msg/Wheel", definition);
  EXPECT_EQ(derived.type_hash, message_traits<golden_msgs::msg::Wheel>::type_hash);
  EXPECT_EQ(derived.schema, std::vector<std::uint8_t>(schema.begin(), schema.end()));
}

TEST(DefinitionType, RefusesWhatItCannotLayOut) {
  const auto refused = [](std::string_view name, std::string_view definition) {
    try {
      type_from_definition(name, definition);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refused("demo/msg/A", "demo/B inner\n").find("no section for demo/B"),
            std::string::npos);
  EXPECT_NE(refused("demo/msg/A", "B inner\n" + std::string(80, '=') + "\nMSG: demo/B\nA outer\n")
                .find("contains itself"),
            std::string::npos);
  EXPECT_NE(refused("demo/msg/A", "int32 x\nint33 y\n").find("demo/A.msg:2"), std::string::npos);
  std::string chain = "L0 next\n";
  for (int i = 0; i < 100000; ++i) {
    chain += std::string(80, '=') + "\nMSG: demo/L" + std::to_string(i) + "\nL" +
             std::to_string(i + 1) + " next\n";
  }
  EXPECT_NE(refused("demo/msg/A", chain).find("nests messages more than 32 deep"),
            std::string::npos);
  EXPECT_NE(refused("not a type", "int32 x\n").find("not a message type name"), std::string::npos);
  EXPECT_NE(refused("demo/msg/A", "int32[0] x\n").find("bad array length '0'"), std::string::npos);
  EXPECT_NE(refused("demo/msg/A", "float64[1000000000] x\n").find("more than a message may"),
            std::string::npos);
  EXPECT_NE(refused("demo/msg/A",
                    "B[200] b\n" + std::string(80, '=') + "\nMSG: demo/B\nfloat64[2000000] x\n")
                .find("more than a message may"),
            std::string::npos);
}

TEST(DefinitionType, AnEmptyMessageHoldsOneByteAsGenerated) {
  const DefinitionType empty = type_from_definition("demo/msg/Nothing", "# only a comment\n");
  const Schema schema = parse_schema(empty.schema);
  ASSERT_EQ(schema.types[0].fields.size(), 1u);
  EXPECT_EQ(schema.types[0].fields[0].name, "structure_needs_at_least_one_member");
  EXPECT_EQ(schema.types[0].size, 1u);
}

}  // namespace
}  // namespace agnocast::cli
