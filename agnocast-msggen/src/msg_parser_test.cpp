#include "msg_parser.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "message_set.hpp"

namespace msggen {
namespace {

MessageSpec parse(std::string_view text) { return parse_message(text, "p/msg/M.msg", "p", "M"); }

// The error message of parsing `text`, or "" when it parses.
std::string error_of(std::string_view text) {
  try {
    parse(text);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(MsgParser, ReadsFieldsConstantsAndContainers) {
  const MessageSpec spec = parse(
      "# about M\n\n"
      "int32 ANSWER=42\n"
      "# the stamp\n"
      "builtin_interfaces/Time stamp\n"
      "Other other  # same package\n"
      "string<=5[<=3] names\n"
      "float64[4] values\n"
      "uint8[] data\n");
  EXPECT_EQ(spec.comments, std::vector<std::string>{"about M"});
  ASSERT_EQ(spec.constants.size(), 1u);
  EXPECT_EQ(spec.constants[0].name, "ANSWER");
  EXPECT_EQ(spec.constants[0].initializer, "42");
  ASSERT_EQ(spec.fields.size(), 5u);
  EXPECT_EQ(spec.fields[0].type.package, "builtin_interfaces");
  EXPECT_EQ(spec.fields[0].comments, std::vector<std::string>{"the stamp"});
  EXPECT_EQ(spec.fields[1].type.package, "p");
  EXPECT_EQ(spec.fields[1].type.name, "Other");
  EXPECT_EQ(spec.fields[1].comments, std::vector<std::string>{"same package"});
  EXPECT_EQ(spec.fields[2].type.base, BaseType::String);
  EXPECT_EQ(spec.fields[2].type.string_bound, 5u);
  EXPECT_EQ(spec.fields[2].type.container, Container::Sequence);
  EXPECT_EQ(spec.fields[2].type.length, 3u);
  EXPECT_EQ(spec.fields[3].type.container, Container::FixedArray);
  EXPECT_EQ(spec.fields[3].type.length, 4u);
  EXPECT_EQ(spec.fields[4].type.container, Container::Sequence);
  EXPECT_EQ(spec.fields[4].type.length, 0u);
  EXPECT_EQ(spec.fields[4].line, 9);
}

TEST(MsgParser, TurnsDefaultsIntoCppValues) {
  const MessageSpec spec = parse(
      "float32 f 0.1\nfloat64 d 1\nbool b True\nint64 i -9223372036854775808\n"
      "string s 'it''s'\nstring t \"a\\\"b\"\nint8[2] a [1, -1]\n");
  EXPECT_EQ(*spec.fields[0].default_initializer, "0.1F");
  EXPECT_EQ(*spec.fields[1].default_initializer, "1.0");
  EXPECT_EQ(*spec.fields[2].default_initializer, "true");
  EXPECT_EQ(*spec.fields[3].default_initializer, "(-9223372036854775807LL - 1)");
  EXPECT_EQ(*spec.fields[5].default_initializer, "\"a\\\"b\"");
  EXPECT_EQ(*spec.fields[6].default_initializer, "{1, -1}");
}

TEST(MsgParser, StringConstantKeepsHashes) {
  const MessageSpec spec = parse("string S=a # b\nint32 I=3 # three\n");
  EXPECT_EQ(spec.constants[0].initializer, "\"a # b\"");
  EXPECT_EQ(spec.constants[1].initializer, "3");
}

// ROS 2's common messages declare constants of many types, e.g.
// diagnostic_msgs/DiagnosticStatus (byte), sensor_msgs/NavSatStatus (int8 < 0, uint16).
TEST(MsgParser, ConstantsOfEveryPrimitiveType) {
  const MessageSpec spec = parse(
      "bool B=True\nbyte Y=255\nchar C=65\nint8 I8 = -128\nuint8 U8=255\nint16 I16=-32768\n"
      "uint16 U16 =  65535\nint32 I32=-2147483648\nuint32 U32=4294967295\n"
      "int64 I64=9223372036854775807\nuint64 U64=18446744073709551615\n"
      "float32 F32=-1.5\nfloat64 F64=1e-3\nstring S='quoted'\nstring<=3 SB=abc\n");
  const std::vector<std::pair<std::string, std::string>> expected{
      {"B", "true"},
      {"Y", "255"},
      {"C", "65"},
      {"I8", "-128"},
      {"U8", "255"},
      {"I16", "-32768"},
      {"U16", "65535"},
      {"I32", "-2147483648"},
      {"U32", "4294967295u"},
      {"I64", "9223372036854775807LL"},
      {"U64", "18446744073709551615ULL"},
      {"F32", "-1.5F"},
      {"F64", "0.001"},
      {"S", "\"quoted\""},
      {"SB", "\"abc\""}};
  ASSERT_EQ(spec.constants.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(spec.constants[i].name, expected[i].first);
    EXPECT_EQ(spec.constants[i].initializer, expected[i].second) << expected[i].first;
  }
  EXPECT_EQ(spec.constants[3].type.base, BaseType::Int8);
  EXPECT_EQ(spec.constants[14].type.string_bound, 3u);
  EXPECT_EQ(error_of("string<=2 S=abc\n"),
            "p/msg/M.msg:1: the string has 3 characters, more than its bound 2");
  EXPECT_EQ(error_of("uint16 S=65536\n"), "p/msg/M.msg:1: 65536 is out of range [0, 65535]");
  EXPECT_EQ(error_of("int8 S=-129\n"), "p/msg/M.msg:1: -129 is out of range [-128, 127]");
}

TEST(MsgParser, EmptyMessageGetsThePlaceholderMember) {
  const MessageSpec spec = parse("# nothing\n");
  ASSERT_EQ(spec.fields.size(), 1u);
  EXPECT_EQ(spec.fields[0].name, "structure_needs_at_least_one_member");
}

TEST(MsgParser, ErrorsNameFileLineAndCause) {
  EXPECT_EQ(error_of("int32 a\nfloat33 b\n"),
            "p/msg/M.msg:2: unknown type 'float33': not a primitive type, and not a message name "
            "(CamelCase)");
  EXPECT_EQ(error_of("string<=0 s\n"),
            "p/msg/M.msg:1: bad string bound '0': expected a positive integer below 2^32");
  EXPECT_EQ(error_of("int32[<=x] a\n"),
            "p/msg/M.msg:1: bad array bound 'x': expected a positive integer below 2^32");
  EXPECT_EQ(
      error_of("int32[99999999999] a\n"),
      "p/msg/M.msg:1: bad array length '99999999999': expected a positive integer below 2^32");
  EXPECT_EQ(error_of("int32 a\n\nint64 a\n"), "p/msg/M.msg:3: duplicate field or constant 'a'");
  EXPECT_EQ(error_of("int32\n"), "p/msg/M.msg:1: expected 'type name', got 'int32'");
  EXPECT_EQ(error_of("int32 Bad\n"),
            "p/msg/M.msg:1: bad field name 'Bad': lower case letters, digits and single "
            "underscores, starting with a letter");
  EXPECT_EQ(error_of("uint8 u 256\n"), "p/msg/M.msg:1: 256 is out of range [0, 255]");
  EXPECT_EQ(error_of("int32[2] a [1]\n"),
            "p/msg/M.msg:1: the array has 1 elements, its type needs 2");
  EXPECT_EQ(error_of("string<=2 s abc\n"),
            "p/msg/M.msg:1: the string has 3 characters, more than its bound 2");
  EXPECT_EQ(error_of("int32 a\n---\n"),
            "p/msg/M.msg:2: '---' separates a service or action, not allowed in a .msg file");
  EXPECT_EQ(error_of("int32 class\n"), "p/msg/M.msg:1: field name 'class' is a C++ keyword");
  EXPECT_EQ(error_of("Other[] X=1\n"),
            "p/msg/M.msg:1: a constant must have a primitive or string type");
}

TEST(MsgParser, BadMessageOrPackageNameIsAboutTheFile) {
  EXPECT_THROW(
      {
        try {
          parse_message("int32 a\n", "x/lower.msg", "p", "lower");
        } catch (const InputError& error) {
          EXPECT_STREQ(error.what(),
                       "x/lower.msg: bad message name 'lower': CamelCase letters and digits");
          throw;
        }
      },
      InputError);
  EXPECT_THROW(parse_message("int32 a\n", "x/M.msg", "Pkg", "M"), InputError);
}

ServiceSpec parse_srv(std::string_view text) {
  return parse_service(text, "p/srv/S.srv", "p", "S");
}

// The error message of parsing `text` as a .srv file, or "" when it parses.
std::string service_error_of(std::string_view text) {
  try {
    parse_srv(text);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(SrvParser, SplitsRequestAndResponseAtTheSeparator) {
  const std::string text =
      "# about the request\n\n"
      "int32 LIMIT=3\n"
      "int64 a 1  # first\n"
      "Other b\n"
      "---\n"
      "int32 LIMIT=4\n"
      "string<=8 a\n";
  const ServiceSpec spec = parse_srv(text);
  EXPECT_EQ(spec.package, "p");
  EXPECT_EQ(spec.name, "S");
  EXPECT_EQ(spec.request.name, "S_Request");
  EXPECT_EQ(spec.response.name, "S_Response");
  EXPECT_EQ(spec.request.kind, "srv");
  EXPECT_EQ(spec.response.kind, "srv");
  EXPECT_EQ(spec.request.comments, std::vector<std::string>{"about the request"});
  ASSERT_EQ(spec.request.constants.size(), 1u);
  EXPECT_EQ(spec.request.constants[0].initializer, "3");
  ASSERT_EQ(spec.request.fields.size(), 2u);
  EXPECT_EQ(*spec.request.fields[0].default_initializer, "1LL");
  EXPECT_EQ(spec.request.fields[0].comments, std::vector<std::string>{"first"});
  // A type of the same package is a message of the package, not a part of a service.
  EXPECT_EQ(spec.request.fields[1].type.package, "p");
  EXPECT_EQ(spec.request.fields[1].type.name, "Other");
  // The same names may appear in both parts; lines count from the file's start.
  ASSERT_EQ(spec.response.constants.size(), 1u);
  EXPECT_EQ(spec.response.constants[0].initializer, "4");
  ASSERT_EQ(spec.response.fields.size(), 1u);
  EXPECT_EQ(spec.response.fields[0].type.string_bound, 8u);
  EXPECT_EQ(spec.response.fields[0].line, 8);
  // Each part's text is its lines of the file; the separator belongs to neither.
  EXPECT_EQ(spec.request.text, text.substr(0, text.find("---\n")));
  EXPECT_EQ(spec.response.text, "int32 LIMIT=4\nstring<=8 a\n");
}

TEST(SrvParser, EmptyPartsGetThePlaceholderMember) {
  const ServiceSpec spec = parse_srv("---");
  EXPECT_EQ(spec.request.text, "");
  EXPECT_EQ(spec.response.text, "");
  ASSERT_EQ(spec.request.fields.size(), 1u);
  EXPECT_EQ(spec.request.fields[0].name, "structure_needs_at_least_one_member");
  ASSERT_EQ(spec.response.fields.size(), 1u);
  EXPECT_EQ(spec.response.fields[0].name, "structure_needs_at_least_one_member");
  // A comment on the separator line is a comment.
  EXPECT_EQ(parse_srv("bool a\n  ---  # then\nbool b\n").response.fields[0].name, "b");
}

TEST(SrvParser, ErrorsNameFileLineAndCause) {
  EXPECT_EQ(service_error_of("int32 a\nint32 b\n"),
            "p/srv/S.srv: no line '---': a service is a request, a line '---', then a response");
  EXPECT_EQ(service_error_of(""),
            "p/srv/S.srv: no line '---': a service is a request, a line '---', then a response");
  EXPECT_EQ(service_error_of("int32 a\n---\nint32 b\n---\nint32 c\n"),
            "p/srv/S.srv:4: a second '---' (the first is on line 2): a service has one request "
            "and one response");
  // Errors in either part are located in the file.
  EXPECT_EQ(service_error_of("int32 a\nfloat33 b\n---\n"),
            "p/srv/S.srv:2: unknown type 'float33': not a primitive type, and not a message name "
            "(CamelCase)");
  EXPECT_EQ(service_error_of("int32 a\n---\nint32 b\n\nint64 b\n"),
            "p/srv/S.srv:5: duplicate field or constant 'b'");
  EXPECT_EQ(service_error_of("---\nuint8 u 256\n"), "p/srv/S.srv:2: 256 is out of range [0, 255]");
  EXPECT_EQ(service_error_of("---\nstring<=2 S=abc\n"),
            "p/srv/S.srv:2: the string has 3 characters, more than its bound 2");
  // A part's name is Name_Request: the service's name has no underscore.
  try {
    parse_service("---\n", "x/srv/lower.srv", "p", "lower");
    FAIL() << "a lower-case service name was accepted";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "x/srv/lower.srv: bad service name 'lower': CamelCase letters and digits");
  }
  EXPECT_THROW(parse_service("---\n", "x/srv/S.srv", "Pkg", "S"), InputError);
}

TEST(MessageSet, ServiceTypesAreResolved) {
  const std::filesystem::path golden = GOLDEN_DIR;
  MessageSet set;
  set.add_input("golden_msgs", golden / "golden_msgs/srv/Steer.srv");
  set.add_package_folder("golden_msgs", golden / "golden_msgs/msg");
  try {
    set.resolve();
    FAIL() << "resolved without the folder of std_msgs";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (golden / "golden_msgs/srv/Steer.srv").string() +
                  ":18: unknown type 'std_msgs/Header': no Header.msg among the inputs or in the "
                  "folders given for package 'std_msgs' (DEPENDENCIES / --include)");
  }
  const std::filesystem::path standard = golden / "../../../messages";
  set.add_package_folder("std_msgs", standard / "std_msgs/msg");
  set.add_package_folder("builtin_interfaces", standard / "builtin_interfaces/msg");
  set.resolve();
  EXPECT_TRUE(set.inputs().empty());
  ASSERT_EQ(set.services().size(), 1u);
  EXPECT_EQ(set.services()[0].name, "Steer");
}

TEST(MessageSet, UnknownTypeNamesWhereToLook) {
  const std::filesystem::path golden = GOLDEN_DIR;
  MessageSet set;
  set.add_input("golden_msgs", golden / "golden_msgs/msg/Wheel.msg");
  try {
    set.resolve();
    FAIL() << "resolved without the folders of std_msgs and golden_msgs";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (golden / "golden_msgs/msg/Wheel.msg").string() +
                  ":10: unknown type 'std_msgs/Header': no Header.msg among the inputs or in the "
                  "folders given for package 'std_msgs' (DEPENDENCIES / --include)");
  }
}

TEST(MessageSet, CyclicIncludeShowsTheChain) {
  const std::filesystem::path cyclic =
      std::filesystem::path(GOLDEN_DIR) / "../cyclic/cyclic_msgs/msg";
  MessageSet set;
  set.add_input("cyclic_msgs", cyclic / "A.msg");
  set.add_package_folder("cyclic_msgs", cyclic);
  try {
    set.resolve();
    FAIL() << "a cycle was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (cyclic / "C.msg").string() +
                  ":1: cyclic include: cyclic_msgs/A -> cyclic_msgs/B -> cyclic_msgs/C -> "
                  "cyclic_msgs/A");
  }
}

}  // namespace
}  // namespace msggen
