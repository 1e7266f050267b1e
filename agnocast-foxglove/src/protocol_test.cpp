#include "protocol.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace agnocast::foxglove {
namespace {

using nlohmann::json;

TEST(Protocol, ServerInfoDeclaresWhatTheServerDoes) {
  const json info = json::parse(server_info_json("agnocast-foxglove", "42"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["capabilities"], json({"clientPublish", "time"}));
  EXPECT_EQ(info["supportedEncodings"], json({"cdr"}));
  EXPECT_EQ(info["sessionId"], "42");
}

TEST(Protocol, AdvertiseCarriesCdrAndRos2msg) {
  const json advertise = json::parse(
      advertise_json({{7, "/points", "sensor_msgs/msg/PointCloud2", "uint32 height\n"}}));
  EXPECT_EQ(advertise["op"], "advertise");
  ASSERT_EQ(advertise["channels"].size(), 1U);
  const json& channel = advertise["channels"][0];
  EXPECT_EQ(channel["id"], 7);
  EXPECT_EQ(channel["topic"], "/points");
  EXPECT_EQ(channel["encoding"], "cdr");
  EXPECT_EQ(channel["schemaName"], "sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(channel["schema"], "uint32 height\n");
  EXPECT_EQ(channel["schemaEncoding"], "ros2msg");
  EXPECT_EQ(json::parse(advertise_json({}))["channels"], json::array());
  EXPECT_EQ(json::parse(unadvertise_json({1, 2}))["channelIds"], json({1, 2}));
}

TEST(Protocol, StatusOfBytesThatAreNotUtf8IsStillJson) {
  const json status = json::parse(status_json(StatusLevel::Error, "bad \xff op"));
  EXPECT_EQ(status["op"], "status");
  EXPECT_EQ(status["level"], 2);
}

TEST(Protocol, MessageDataFrameIsLittleEndian) {
  const std::uint8_t payload[] = {0xAA, 0xBB};
  const std::string frame = message_data_frame(0x01020304, 0x1122334455667788ULL, payload);
  const std::string expected("\x01\x04\x03\x02\x01\x88\x77\x66\x55\x44\x33\x22\x11\xAA\xBB", 15);
  EXPECT_EQ(frame, expected);
  EXPECT_EQ(time_frame(0x0102), std::string("\x02\x02\x01\0\0\0\0\0\0", 9));
}

TEST(Protocol, ParsesTheFourClientOps) {
  const ClientRequest subscribe = parse_client_request(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":1,"channelId":5}]})");
  ASSERT_TRUE(std::holds_alternative<Subscribe>(subscribe));
  ASSERT_EQ(std::get<Subscribe>(subscribe).subscriptions.size(), 2U);
  EXPECT_EQ(std::get<Subscribe>(subscribe).subscriptions[1].channel_id, 5U);

  const ClientRequest unsubscribe =
      parse_client_request(R"({"op":"unsubscribe","subscriptionIds":[4]})");
  EXPECT_EQ(std::get<Unsubscribe>(unsubscribe).subscription_ids, std::vector<std::uint32_t>{4});

  const ClientRequest advertise = parse_client_request(
      R"({"op":"advertise","channels":[{"id":1,"topic":"/cmd","encoding":"cdr","schemaName":"std_msgs/msg/String"}]})");
  const auto& channel = std::get<ClientAdvertise>(advertise).channels.at(0);
  EXPECT_EQ(channel.topic, "/cmd");
  EXPECT_EQ(channel.encoding, "cdr");
  EXPECT_EQ(channel.schema_name, "std_msgs/msg/String");

  const ClientRequest unadvertise =
      parse_client_request(R"({"op":"unadvertise","channelIds":[1]})");
  EXPECT_EQ(std::get<ClientUnadvertise>(unadvertise).channel_ids, std::vector<std::uint32_t>{1});
}

TEST(Protocol, RefusesWhatIsMalformed) {
  for (const char* text :
       {"", "{", "[]", "42", R"({"op":1})", R"({"op":"fly"})", R"({"op":"subscribe"})",
        R"({"op":"subscribe","subscriptions":{}})", R"({"op":"subscribe","subscriptions":[1]})",
        R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})",
        R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})",
        R"({"op":"unsubscribe","subscriptionIds":["a"]})",
        R"({"op":"advertise","channels":[{"id":1,"topic":"/x","encoding":"cdr"}]})"}) {
    EXPECT_THROW(parse_client_request(text), ProtocolError) << text;
  }
}

TEST(Protocol, ParsesClientMessageFrames) {
  const std::string frame("\x01\x02\x00\x00\x00\xAB", 6);  // the payload points into it
  const ClientMessage message = parse_client_message(frame);
  EXPECT_EQ(message.channel_id, 2U);
  ASSERT_EQ(message.payload.size(), 1U);
  EXPECT_EQ(message.payload[0], 0xAB);
  EXPECT_THROW(parse_client_message(""), ProtocolError);
  EXPECT_THROW(parse_client_message(std::string("\x01\x02\x00", 3)), ProtocolError);
  EXPECT_THROW(parse_client_message(std::string("\x02\x02\x00\x00\x00", 5)), ProtocolError);
}

}  // namespace
}  // namespace agnocast::foxglove
