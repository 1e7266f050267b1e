// agnocast-msggen's .msg and .srv grammar over any text: a spec or an
// InputError naming the line, nothing else.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "msg_parser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    msggen::parse_message(text, "fuzz.msg", "fuzz_msgs", "Fuzz");
  } catch (const msggen::InputError&) {
  }
  try {
    msggen::parse_service(text, "fuzz.srv", "fuzz_msgs", "Fuzz");
  } catch (const msggen::InputError&) {
  }
  return 0;
}
