// The service of the round-trip benchmarks: its request and its response
// each carry the payload, as a topic's BenchMessage does.  The ping-pong
// reference sends the same two types over two topics.
#pragma once

#include <agnocast/agnocast.hpp>
#include <agnocast/service.hpp>
#include <cstdint>
#include <string_view>

namespace agnocast::bench {

struct BenchRequest {
  std::uint64_t seq = 0;
  agnocast::vector<std::uint8_t> payload;
};
struct BenchResponse {
  std::uint64_t seq = 0;
  agnocast::vector<std::uint8_t> payload;
};
struct BenchService {
  using Request = BenchRequest;
  using Response = BenchResponse;
};

}  // namespace agnocast::bench

AGNOCAST_MESSAGE(agnocast::bench::BenchRequest, "agnocast_bench/srv/BenchService_Request", seq,
                 payload);
AGNOCAST_MESSAGE(agnocast::bench::BenchResponse, "agnocast_bench/srv/BenchService_Response", seq,
                 payload);

// What agnocast-msggen writes for a .srv file, written here as the messages are.
template <>
struct agnocast::service_traits<agnocast::bench::BenchService> {
  static constexpr bool is_declared = true;
  static constexpr std::string_view type_name = "agnocast_bench/srv/BenchService";
  static constexpr std::uint64_t request_type_hash =
      message_traits<agnocast::bench::BenchRequest>::type_hash;
  static constexpr std::uint64_t response_type_hash =
      message_traits<agnocast::bench::BenchResponse>::type_hash;
};
