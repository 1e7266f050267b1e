// The limits the library enforces on what a program asks of it, in one place.
// Most mirror the kernel module's UAPI (<agnocast.h>); the library's device
// layer (src/kernel/device.cpp, the one source that includes the UAPI header) checks
// at compile time that each still agrees with the kernel's constant. Programs
// that validate a configuration before they create endpoints (agnocast-bridge
// --check-config) take their bounds from here, so that what they accept the
// library accepts too.
#pragma once

#include <cstddef>

namespace agnocast {

// QoS depth: how many newest messages the kernel keeps per publisher
// (AGNOCAST_DEPTH_MAX). QoS{n} with n outside [min, max] is refused.
inline constexpr std::size_t qos_depth_min = 1;
inline constexpr std::size_t qos_depth_max = 1024;

// Linux refuses message queue names longer than NAME_MAX (after the leading '/').
inline constexpr std::size_t queue_name_max = 255;
// The longest decimal subscriber id (UINT32_MAX has 10 digits).
inline constexpr std::size_t subscriber_id_digits_max = 10;
// Topic names, in characters. The kernel takes up to AGNOCAST_TOPIC_NAME_MAX - 1;
// the library allows fewer, so that a subscriber's queue name fits NAME_MAX for
// every possible id: topic (with its leading '/') - 1 + '@' + 10 digits <= 255.
// The characters allowed are topic_name_problem()'s (<agnocast/naming.hpp>).
inline constexpr std::size_t topic_name_max = queue_name_max - subscriber_id_digits_max;

// Node names and message type names, in characters: the kernel's label sizes
// (AGNOCAST_NODE_NAME_MAX, AGNOCAST_TYPE_NAME_MAX) less their NUL.
inline constexpr std::size_t node_name_max = 127;
inline constexpr std::size_t type_name_max = 127;

// The schema the kernel stores per topic, in bytes (AGNOCAST_SCHEMA_MAX): the
// fields of every type it nests and their .msg texts.
inline constexpr std::size_t schema_max_bytes = 65536;
// How deep messages may nest in a schema (the message itself is level 1):
// readers of foreign messages recurse once per level. ROS 2's standard types
// nest at most 5 deep.
inline constexpr std::size_t message_max_nesting = 32;

// Endpoints of one topic (AGNOCAST_PUBLISHERS_PER_TOPIC_MAX,
// AGNOCAST_SUBSCRIBERS_PER_TOPIC_MAX).
inline constexpr std::size_t publishers_per_topic_max = 1024;
inline constexpr std::size_t subscribers_per_topic_max = 1024;

// An access policy's rules, and the users and groups all its rules name
// together (AGNOCAST_POLICY_RULES_MAX, AGNOCAST_POLICY_PRINCIPALS_MAX).
inline constexpr std::size_t access_policy_rules_max = 256;
inline constexpr std::size_t access_policy_principals_max = 4096;

}  // namespace agnocast
