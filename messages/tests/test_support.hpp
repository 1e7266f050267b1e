// What the standard set's tests share: a test pool, and sample messages
// written from a type's schema alone (not by its generated serializer).
#pragma once

#include <agnocast/schema.hpp>
#include <cstdint>
#include <vector>

namespace standard_messages_test {

// Messages allocate their containers in the process's pool: a test pool, once.
void install_test_runtime();

// XCDR1 bytes of a message with every field set, encapsulation header
// included. No value is the type's default: numbers are non-zero and differ
// from field to field and with seed, bools are true, strings and unbounded
// sequences are not empty. A bounded sequence or string holds exactly its
// bound when that is small, so values at the bound make the round trip too.
std::vector<std::uint8_t> sample_cdr(const agnocast::Schema& schema, std::uint32_t seed);

}  // namespace standard_messages_test
