#include "access_principal.hpp"

#include <grp.h>
#include <pwd.h>

#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace agnocastd {
namespace {

using agnocast::AccessPrincipal;

std::optional<std::uint32_t> numeric_id(std::string_view digits) {
  std::uint32_t id = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), id);
  if (digits.empty() || error != std::errc{} || end != digits.data() + digits.size()) {
    return std::nullopt;
  }
  // (uid_t)-1 means "no id" to the kernel's id calls.
  if (id == std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
  return id;
}

// getpwnam_r/getgrnam_r with a buffer that grows on ERANGE; nullopt when absent.
template <typename Entry, typename Lookup, typename IdOf>
std::optional<std::uint32_t> lookup_id(const std::string& name, Lookup lookup, IdOf id_of,
                                       std::string_view database) {
  std::vector<char> buffer(1024);
  for (;;) {
    Entry entry{};
    Entry* found = nullptr;
    const int error = lookup(name.c_str(), &entry, buffer.data(), buffer.size(), &found);
    if (error == ERANGE && buffer.size() < (1u << 20)) {
      buffer.resize(buffer.size() * 2);
      continue;
    }
    // ENOENT, ESRCH, EBADF and EPERM mean "no such name" for some NSS modules.
    if (found != nullptr) return id_of(*found);
    if (error == 0 || error == ENOENT || error == ESRCH || error == EBADF || error == EPERM) {
      return std::nullopt;
    }
    throw std::invalid_argument("cannot look up '" + name + "' in the " + std::string(database) +
                                " database: " + std::strerror(error));
  }
}

}  // namespace

AccessPrincipal parse_access_principal(std::string_view text) {
  if (text == "*") return {AccessPrincipal::Kind::anyone, 0};
  const auto colon = text.find(':');
  const std::string_view kind = text.substr(0, colon);
  const std::string name(colon == text.npos ? std::string_view{} : text.substr(colon + 1));
  if (colon == text.npos || (kind != "user" && kind != "group") || name.empty()) {
    throw std::invalid_argument(
        "expected \"user:NAME\", \"group:NAME\" (or a numeric id) or "
        "\"*\", got \"" +
        std::string(text) + "\"");
  }
  // The name databases take C strings: "root\0x" would be looked up as "root".
  if (name.find('\0') != std::string::npos) {
    throw std::invalid_argument("a " + std::string(kind) + " name may not hold a NUL byte");
  }
  const bool user = kind == "user";
  const auto principal_kind = user ? AccessPrincipal::Kind::user : AccessPrincipal::Kind::group;
  if (name.find_first_not_of("0123456789") == name.npos) {
    const auto id = numeric_id(name);
    if (!id) throw std::invalid_argument("id " + name + " is out of range");
    return {principal_kind, *id};
  }
  const auto id = user ? lookup_id<passwd>(
                             name, ::getpwnam_r, [](const passwd& p) { return p.pw_uid; }, "passwd")
                       : lookup_id<group>(
                             name, ::getgrnam_r, [](const group& g) { return g.gr_gid; }, "group");
  if (!id) throw std::invalid_argument("no " + std::string(kind) + " named '" + name + "'");
  return {principal_kind, *id};
}

}  // namespace agnocastd
