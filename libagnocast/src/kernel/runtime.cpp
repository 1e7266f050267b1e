#include "kernel/runtime.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <pthread.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <iterator>
#include <sstream>
#include <utility>
#include <vector>

#include "agnocast/allocator.hpp"
#include "agnocast/detail/message.hpp"
#include "agnocast/errors.hpp"
#include "kernel/device.hpp"
#include "memory/heap_hook.hpp"

namespace agnocast::detail {
namespace {

std::atomic<Runtime*> instance{nullptr};
std::mutex init_mutex;

std::string address_hex(std::uint64_t value) {
  std::ostringstream out;
  out << "0x" << std::hex << value;
  return out.str();
}

[[noreturn]] void throw_errno(const std::string& what, int err) {
  throw Error("agnocast: " + what + ": " + std::strerror(err));
}

// What to do when an address range is taken.  AddressSanitizer's runtime
// reserves its shadow memory at start, below 0x10007fff8000: a module loaded
// with a pool_base there puts pools where no such process can map them.
// (ThreadSanitizer's runtime stops the process itself, naming the address.)
std::string occupied_hint() {
  std::string hint = "; something else occupies that address range";
  if (::dlsym(RTLD_DEFAULT, "__asan_init") != nullptr) {
    hint +=
        " (this process runs under AddressSanitizer, whose shadow memory may cover it: load "
        "agnocast.ko with a pool_base above 0x10007fff8000, as its default 0x200000000000 is)";
  }
  return hint;
}

// Maps fd at exactly addr, refusing to replace anything unless replace is set.
void map_at(std::uint64_t addr, std::uint64_t size, int prot, int fd, bool replace,
            const std::string& what) {
  void* wanted = reinterpret_cast<void*>(addr);
  const int flags = MAP_SHARED | (replace ? MAP_FIXED : MAP_FIXED_NOREPLACE);
  void* mapped = ::mmap(wanted, size, prot, flags, fd, 0);
  if (mapped == MAP_FAILED) {
    const int err = errno;
    throw Error("agnocast: cannot map " + what + " at " + address_hex(addr) + " (" +
                std::to_string(size) + " bytes): " + std::strerror(err) +
                (err == EEXIST ? occupied_hint() : ""));
  }
  if (mapped != wanted) {  // kernels before 4.17 treat MAP_FIXED_NOREPLACE as a hint
    ::munmap(mapped, size);
    throw Error("agnocast: cannot map " + what + " at " + address_hex(addr) +
                ": the kernel placed it elsewhere");
  }
}

}  // namespace

Runtime::Runtime(std::unique_ptr<Kernel> kernel, pid_t pid, void* pool_addr, std::size_t pool_size)
    : kernel_(std::move(kernel)),
      pid_(pid),
      pool_addr_(pool_addr),
      pool_size_(pool_size),
      pool_(pool_addr, pool_size) {}

Runtime* Runtime::current() noexcept { return instance.load(std::memory_order_acquire); }

Runtime& Runtime::get() {
  if (Runtime* runtime = current()) return *runtime;
  std::lock_guard lock(init_mutex);
  if (Runtime* runtime = current()) return *runtime;
  static std::once_flag fork_handler_installed;
  std::call_once(fork_handler_installed, [] {
    // Holding init_mutex across fork keeps the child from inheriting it locked.
    ::pthread_atfork([] { init_mutex.lock(); }, [] { init_mutex.unlock(); },
                     [] {
                       init_mutex.unlock();
                       forget_in_fork_child();
                     });
  });
  Runtime* runtime = create();
  instance.store(runtime, std::memory_order_release);
  return *runtime;
}

Runtime* Runtime::create() {
  Device device = Device::open();
  const Version module = device.get_version();
  if (!is_compatible(module)) {
    throw VersionMismatch("agnocast kernel module version " + module.to_string() +
                          " is incompatible with library version " +
                          std::string(library_version_string) +
                          " (major.minor must match): install matching versions and restart "
                          "agnocastd");
  }
  const PoolSlot slot = device.register_process(-1);
  // From here on, every failure undoes what was done so far.
  int memfd = -1;
  bool mapped = false;
  try {
    memfd = ::memfd_create("agnocast_pool", MFD_CLOEXEC | MFD_ALLOW_SEALING);
    if (memfd < 0) throw_errno("memfd_create for the shared pool", errno);
    if (::ftruncate(memfd, static_cast<off_t>(slot.size)) != 0) {
      throw_errno("sizing the shared pool to " + std::to_string(slot.size) + " bytes", errno);
    }
    map_at(slot.addr, slot.size, PROT_READ | PROT_WRITE, memfd, /*replace=*/false,
           "this process's pool");
    mapped = true;
    seal_pool(memfd);
    device.register_process(memfd);
    ::close(std::exchange(memfd, -1));  // the mapping keeps the file alive
  } catch (...) {
    if (mapped) ::munmap(reinterpret_cast<void*>(slot.addr), slot.size);
    if (memfd >= 0) ::close(memfd);
    try {
      device.unregister_process();
    } catch (const DeviceError&) {
      // Nothing more to undo: closing the device drops the registration too.
    }
    throw;
  }
  auto* runtime = new Runtime(std::make_unique<Device>(std::move(device)), slot.pid,
                              reinterpret_cast<void*>(slot.addr), slot.size);
  runtime->pool_mapped_here_ = true;
  attach_pool_to_heap_hook(runtime->pool_addr_, runtime->pool_size_);
  return runtime;
}

Runtime& Runtime::install_for_testing(void* region, std::size_t size,
                                      std::unique_ptr<Kernel> kernel) {
  std::lock_guard lock(init_mutex);
  Runtime* runtime = new Runtime(std::move(kernel), ::getpid(), region, size);
  // Earlier test runtimes are kept, never freed: pointers into them may
  // survive. Kept reachable to the end (a list never destroyed), so
  // LeakSanitizer, which looks after static destructors, does not count them.
  static auto* const retired = new std::vector<Runtime*>;
  if (Runtime* earlier = instance.exchange(runtime, std::memory_order_acq_rel)) {
    retired->push_back(earlier);
  }
  attach_pool_to_heap_hook(region, size);
  return *runtime;
}

// The child shares the parent's pool file: it must not allocate in it, nor
// look like the parent to the kernel. Unmap everything and start afresh on
// next use. The old object is leaked: its mutexes may be held by threads
// that do not exist in the child.
void Runtime::forget_in_fork_child() noexcept {
  Runtime* runtime = instance.exchange(nullptr);
  if (!runtime || !runtime->pool_mapped_here_) return;
  ::munmap(runtime->pool_addr_, runtime->pool_size_);
  for (const auto& [addr, size] : runtime->mapped_pools_) {
    ::munmap(reinterpret_cast<void*>(addr), size);
  }
  runtime->kernel_->close();
}

// On a full pool: first take back what nobody references any more, then
// ask the kernel to drop entries that only slow subscribers still wait for
// (beyond the publisher's depth), and take those back too.
void* Runtime::allocate(std::size_t size, std::size_t align) {
  for (int attempt = 0;; ++attempt) {
    {
      std::lock_guard lock(pool_mutex_);
      if (void* ptr = pool_.allocate(size, align)) return ptr;
    }
    if (attempt == 2 || !kernel_) break;
    if (attempt == 1) kernel_->shed();
    reclaim_all();
  }
  throw PoolExhausted(
      "agnocast: the shared pool of this process (" + std::to_string(pool_size_ >> 20) +
      " MiB) has no room for " + std::to_string(size) +
      " bytes: raise the module parameter pool_size (\"module_parameters\": {\"pool_size\": "
      "BYTES} in /etc/agnocast/agnocastd.json, or modprobe agnocast pool_size=BYTES), or hold "
      "fewer messages");
}

void Runtime::deallocate(void* ptr) noexcept {
  if (!ptr || !pool_.owns(ptr)) return;  // never free into another process's pool
  std::lock_guard lock(pool_mutex_);
  pool_.free(ptr);
}

std::size_t Runtime::usable_size(const void* ptr) const {
  std::lock_guard lock(pool_mutex_);
  return pool_.usable_size(ptr);
}

Tlsf::Stats Runtime::pool_stats() const {
  std::lock_guard lock(pool_mutex_);
  Tlsf::Stats stats;
  pool_.check(&stats);
  return stats;
}

void Runtime::free_reclaimed(std::span<const std::uint64_t> addresses) noexcept {
  for (std::uint64_t address : addresses) {
    void* message = reinterpret_cast<void*>(address);
    if (!owns(message)) continue;
    discard_message(message);
  }
}

void Runtime::defer_free(std::span<const std::uint64_t> addresses) noexcept {
  if (addresses.empty()) return;
  {
    std::lock_guard lock(deferred_mutex_);
    if (deferred_count_ + addresses.size() <= deferred_.size()) {
      std::copy(addresses.begin(), addresses.end(), deferred_.begin() + deferred_count_);
      deferred_count_ += addresses.size();
      deferred_waiting_.store(true, std::memory_order_release);
      return;
    }
  }
  free_reclaimed(addresses);
}

void Runtime::free_deferred() noexcept {
  if (!deferred_waiting_.load(std::memory_order_acquire)) return;
  std::array<std::uint64_t, deferred_max> batch;
  std::size_t count;
  {
    std::lock_guard lock(deferred_mutex_);
    count = std::exchange(deferred_count_, 0);
    std::copy_n(deferred_.begin(), count, batch.begin());
    deferred_waiting_.store(false, std::memory_order_relaxed);
  }
  free_reclaimed(std::span(batch.data(), count));
}

void Runtime::reclaim_all() {
  free_deferred();
  std::vector<std::uint64_t> addresses(256);
  for (;;) {
    const ReclaimResult result = kernel_->reclaim(addresses);
    free_reclaimed(std::span(addresses.data(), result.reclaim_count));
    if (result.reclaim_pending == 0) break;
  }
}

void Runtime::map_pool(const PoolGrant& grant) {
  struct CloseOnExit {
    int fd;
    ~CloseOnExit() { ::close(fd); }
  } close_fd{grant.fd};
  if (grant.addr == reinterpret_cast<std::uint64_t>(pool_addr_)) return;  // our own pool
  std::lock_guard lock(mapped_mutex_);
  // A slot freed by a dead publisher comes back with a new pool: replace our old view.
  const bool replace = mapped_pools_.contains(grant.addr);
  map_at(grant.addr, grant.size, PROT_READ, grant.fd, replace,
         "the pool of publisher pid " + std::to_string(grant.pid));
  mapped_pools_[grant.addr] = grant.size;
}

std::span<const std::byte> Runtime::pool_holding(const void* address) {
  const auto at = reinterpret_cast<std::uint64_t>(address);
  const auto own = reinterpret_cast<std::uint64_t>(pool_addr_);
  if (at >= own && at - own < pool_size_) {
    return {static_cast<const std::byte*>(pool_addr_), pool_size_};
  }
  std::lock_guard lock(mapped_mutex_);
  auto after = mapped_pools_.upper_bound(at);
  if (after == mapped_pools_.begin()) return {};
  const auto& [addr, size] = *std::prev(after);
  if (at - addr >= size) return {};
  return {reinterpret_cast<const std::byte*>(addr), static_cast<std::size_t>(size)};
}

}  // namespace agnocast::detail
