// Coverage guidance for the module's fuzzer (fuzz_test.cpp) from kcov: a
// kernel with CONFIG_KCOV and a module built with KCOV_INSTRUMENT (the debug
// kernel's, AGNOCAST_COVERAGE=1) list, per thread, the module's basic blocks
// each system call ran.  A fuzzing step is a function of the random values it
// draws; a step whose blocks make an edge (a pair of blocks in a row) no step
// made before keeps its values as an input of a corpus, which later steps
// replay with a few values changed.
#pragma once

#include <fcntl.h>
#include <linux/kcov.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

namespace agnocast_test {

// One thread's kcov: opened (as root: debugfs is root's) by any thread, then
// enabled by the thread it traces.  Where the kernel has no kcov it stays
// closed and traces nothing.
class KcovTrace {
 public:
  static constexpr size_t kMaxPcs = 1 << 16;

  KcovTrace() {
    fd_ = open("/sys/kernel/debug/kcov", O_RDWR | O_CLOEXEC);
    if (fd_ < 0) return;
    void* area = MAP_FAILED;
    if (ioctl(fd_, KCOV_INIT_TRACE, kMaxPcs) == 0)
      area = mmap(nullptr, kMaxPcs * sizeof(uint64_t), PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
    if (area == MAP_FAILED) {
      close(fd_);
      fd_ = -1;
      return;
    }
    area_ = static_cast<std::atomic<uint64_t>*>(area);
  }
  ~KcovTrace() {
    if (area_) munmap(area_, kMaxPcs * sizeof(uint64_t));
    if (fd_ >= 0) close(fd_);
  }
  KcovTrace(const KcovTrace&) = delete;
  KcovTrace& operator=(const KcovTrace&) = delete;

  bool available() const { return area_ != nullptr; }

  // Starts a trace of the calling thread's system calls; false if this
  // thread cannot be traced (no kcov, or another thread's trace: a fork
  // child's copy of its parent's).
  bool start() {
    if (!area_) return false;
    const pid_t tid = static_cast<pid_t>(syscall(SYS_gettid));
    if (owner_ == 0) {
      if (ioctl(fd_, KCOV_ENABLE, KCOV_TRACE_PC)) {
        munmap(area_, kMaxPcs * sizeof(uint64_t));
        area_ = nullptr;
        return false;
      }
      owner_ = tid;
    }
    if (owner_ != tid) return false;
    area_[0].store(0, std::memory_order_relaxed);
    return true;
  }

  // The blocks run since start(), in order (the kernel writes them).
  std::span<const uint64_t> pcs() const {
    const uint64_t n = std::min<uint64_t>(area_[0].load(std::memory_order_relaxed), kMaxPcs - 1);
    return {reinterpret_cast<const uint64_t*>(area_ + 1), static_cast<size_t>(n)};
  }

 private:
  int fd_ = -1;
  std::atomic<uint64_t>* area_ = nullptr;
  pid_t owner_ = 0;
};

// The edges seen and the corpus, shared by every process of a run (it lives
// in the fuzzer's shared mapping, zeroed).  A torn read of an input is only
// another input.
struct CoverageGuide {
  static constexpr size_t kMapSize = 1 << 16;
  static constexpr size_t kCorpusSize = 1024;
  static constexpr size_t kInputMax = 48;
  static constexpr uint64_t kRecent = 16;

  std::atomic<uint8_t> map[kMapSize];
  std::atomic<uint64_t> edges;   // distinct edges (map slots) seen
  std::atomic<uint64_t> inputs;  // inputs kept; the corpus keeps the newest kCorpusSize
  struct Input {
    std::atomic<uint32_t> length;
    std::atomic<uint64_t> values[kInputMax];
  } corpus[kCorpusSize];

  // Counts a trace's edges; returns how many no trace had before.
  uint64_t merge(std::span<const uint64_t> pcs) {
    uint64_t fresh = 0, previous = 0;
    for (uint64_t pc : pcs) {
      const uint64_t slot = (hash(previous) >> 1 ^ hash(pc)) % kMapSize;
      previous = pc;
      if (map[slot].load(std::memory_order_relaxed)) continue;
      if (map[slot].exchange(1, std::memory_order_relaxed) == 0) fresh++;
    }
    if (fresh) edges.fetch_add(fresh, std::memory_order_relaxed);
    return fresh;
  }

  void keep(const std::vector<uint64_t>& values) {
    Input& input = corpus[inputs.fetch_add(1, std::memory_order_relaxed) % kCorpusSize];
    const size_t n = std::min(values.size(), kInputMax);
    for (size_t i = 0; i < n; i++) input.values[i].store(values[i], std::memory_order_relaxed);
    input.length.store(static_cast<uint32_t>(n), std::memory_order_relaxed);
  }

  // A kept input, picked by @choice: half of the picks among the newest
  // kRecent, which found the rarest edges so far.  Empty while none is kept.
  std::vector<uint64_t> pick(uint64_t choice) const {
    const uint64_t total = inputs.load(std::memory_order_relaxed);
    const uint64_t kept = std::min<uint64_t>(total, kCorpusSize);
    if (kept == 0) return {};
    const uint64_t index = choice % 2
                               ? (total - 1 - choice / 2 % std::min(kept, kRecent)) % kCorpusSize
                               : choice / 2 % kept;
    const Input& input = corpus[index];
    std::vector<uint64_t> values(
        std::min<size_t>(input.length.load(std::memory_order_relaxed), kInputMax));
    for (size_t i = 0; i < values.size(); i++)
      values[i] = input.values[i].load(std::memory_order_relaxed);
    return values;
  }

 private:
  static uint64_t hash(uint64_t x) {
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    return x ^ x >> 33;
  }
};

// A step's random source: hands out fresh values, or replays an input's and
// goes on with fresh ones past its end; either way it records what it handed
// out, which is the step's input.  A UniformRandomBitGenerator.
class TapedRng {
 public:
  using result_type = uint64_t;
  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return UINT64_MAX; }

  explicit TapedRng(uint64_t seed) : fresh_(seed) {}

  result_type operator()() {
    const uint64_t value = next_ < replay_.size() ? replay_[next_++] : fresh_();
    if (tape_.size() < CoverageGuide::kInputMax) tape_.push_back(value);
    return value;
  }

  // A value for the guidance itself, outside any step's input.
  uint64_t fresh() { return fresh_(); }

  // Starts a step on fresh values (@replay empty) or on @replay's.
  void begin(std::vector<uint64_t> replay = {}) {
    replay_ = std::move(replay);
    next_ = 0;
    tape_.clear();
  }

  const std::vector<uint64_t>& tape() const { return tape_; }

 private:
  std::mt19937_64 fresh_;
  std::vector<uint64_t> replay_;
  size_t next_ = 0;
  std::vector<uint64_t> tape_;
};

// An input changed a little: one to three values drawn afresh, and at times
// cut short (the rest fresh too).
inline std::vector<uint64_t> mutate(std::vector<uint64_t> input, TapedRng& rng) {
  if (input.empty()) return input;
  for (uint64_t n = 1 + rng.fresh() % 3; n > 0; n--)
    input[rng.fresh() % input.size()] = rng.fresh();
  if (rng.fresh() % 4 == 0) input.resize(rng.fresh() % input.size());
  return input;
}

}  // namespace agnocast_test
