// How rmw_cyclonedds_cpp carries a service call on DDS: a request or reply
// sample is the XCDR1 encapsulation header (4 bytes), then a 16-byte request
// header in the writer's native byte order, then the request or response as
// an ordinary message. The header names the call: the requesting client (the
// instance handle of its request writer) and the client's sequence number; a
// reply repeats its request's header, and each client keeps the replies that
// name it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace agnocast_bridge {

struct DdsRequestHeader {
  std::uint64_t client = 0;  // the requesting client's request writer (instance handle)
  std::int64_t sequence = 0;

  bool operator==(const DdsRequestHeader&) const = default;
};

inline constexpr std::size_t dds_request_header_size = 16;

// message: what agnocast::cdr::serialize wrote (encapsulation header first).
// Returns the sample's bytes: the header inserted after the encapsulation header.
std::vector<std::uint8_t> with_request_header(const DdsRequestHeader& header,
                                              std::vector<std::uint8_t> message);

struct SplitSample {
  DdsRequestHeader header;
  std::vector<std::uint8_t> message;  // encapsulation header, then the message
};
// The header and the message of a sample; nullopt for one too short to hold them.
std::optional<SplitSample> split_request_header(std::span<const std::uint8_t> sample);

// What rmw_cyclonedds_cpp puts in the USER_DATA of a service's or a client's
// reader and writer ("serviceid=<id>;" / "clientid=<id>;"), so that a peer
// tells which reader and writer belong together; id is unique per endpoint pair.
std::string service_user_data(const char* key, std::span<const std::uint8_t, 16> id);

}  // namespace agnocast_bridge
