#pragma once

#include <cstddef>

namespace agnocast {

// How many newest messages the kernel keeps per publisher for subscribers that
// have not received them, and whether late subscribers get them (both sides
// must be transient-local for that).
class QoS {
 public:
  explicit QoS(std::size_t depth) : depth_(depth) {}

  QoS& transient_local() {
    transient_local_ = true;
    return *this;
  }

  std::size_t depth() const { return depth_; }
  bool is_transient_local() const { return transient_local_; }

 private:
  std::size_t depth_;
  bool transient_local_ = false;
};

}  // namespace agnocast
