#include "header_writer.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "message_set.hpp"

namespace msggen {
namespace {

const std::filesystem::path golden = GOLDEN_DIR;
const std::filesystem::path standard = std::filesystem::path(GOLDEN_DIR) / "../../../messages";

std::string read(const std::filesystem::path& path) {
  std::ifstream stream(path);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

TEST(HeaderWriter, SnakeCaseFollowsRos2) {
  EXPECT_EQ(snake_case("PointCloud2"), "point_cloud2");
  EXPECT_EQ(snake_case("PoseStamped"), "pose_stamped");
  EXPECT_EQ(snake_case("Imu"), "imu");
  EXPECT_EQ(snake_case("TFMessage"), "tf_message");
  EXPECT_EQ(snake_case("Vector3"), "vector3");
  EXPECT_EQ(header_path("wheel_msgs", "Wheel"), "wheel_msgs/msg/wheel.hpp");
  EXPECT_EQ(service_header_path("std_srvs", "SetBool"), "std_srvs/srv/set_bool.hpp");
}

// The .msg text as string literals that say exactly its bytes: quotes,
// backslashes, '?' (no trigraph), tabs, control and non-ASCII bytes escaped,
// one literal per line, and a last line without its newline kept so.
TEST(HeaderWriter, DefinitionIsALiteralOfTheFilesBytes) {
  MessageSpec spec;
  spec.package = "edge_msgs";
  spec.name = "Edge";
  spec.text = "# \"q\" \\ ?\?= \t\r gr\xc3\xbc\xc3\x9f\xc3\xa9\nint32 x\n\nint32 y";
  const std::string header = write_header(spec);
  EXPECT_NE(header.find(
                "  static constexpr std::string_view definition =\n"
                "      \"# \\\"q\\\" \\\\ \\?\\?= \\t\\015 gr\\303\\274\\303\\237\\303\\251\\n\"\n"
                "      \"int32 x\\n\"\n"
                "      \"\\n\"\n"
                "      \"int32 y\";\n"),
            std::string::npos)
      << header;
  spec.text.clear();
  EXPECT_NE(write_header(spec).find("definition =\n      \"\";\n"), std::string::npos);
}

// Regenerate the expected files, in agnocast-msggen/, with:
//   agnocast-msggen --package golden_msgs --output-dir tests/golden/expected
//     --include golden_msgs=tests/golden/golden_msgs/msg
//     --include std_msgs=../messages/std_msgs/msg
//     --include geometry_msgs=../messages/geometry_msgs/msg
//     --include builtin_interfaces=../messages/builtin_interfaces/msg
//     tests/golden/golden_msgs/msg/*.msg tests/golden/golden_msgs/srv/*.srv
TEST(HeaderWriter, MatchesGoldenHeaders) {
  MessageSet set;
  for (const char* package : {"std_msgs", "geometry_msgs", "builtin_interfaces"}) {
    set.add_package_folder(package, standard / package / "msg");
  }
  set.add_package_folder("golden_msgs", golden / "golden_msgs/msg");
  for (const char* name : {"Empty", "Tire", "Wheel"}) {
    set.add_input("golden_msgs", golden / "golden_msgs/msg" / (std::string(name) + ".msg"));
  }
  set.add_input("golden_msgs", golden / "golden_msgs/srv/Steer.srv");
  set.resolve();
  ASSERT_EQ(set.inputs().size(), 3u);
  for (const MessageSpec& spec : set.inputs()) {
    const auto expected = golden / "expected" / header_path(spec.package, spec.name);
    EXPECT_EQ(write_header(spec), read(expected)) << "differs from " << expected;
  }
  ASSERT_EQ(set.services().size(), 1u);
  const ServiceSpec& steer = set.services()[0];
  const auto expected = golden / "expected" / service_header_path(steer.package, steer.name);
  EXPECT_EQ(write_service_header(steer), read(expected)) << "differs from " << expected;
}

}  // namespace
}  // namespace msggen
