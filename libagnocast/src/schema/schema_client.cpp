#include "agnocast/schema_client.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <mutex>
#include <system_error>
#include <utility>

#include "agnocast/detail/message.hpp"
#include "schema/cdr_to_pool.hpp"

namespace agnocast {
namespace {

// One blocking call's answer, handed over by whichever thread receives it:
// call() itself, or an executor spinning the node meanwhile, which then
// wakes call() through `ready`.
class Answer {
 public:
  Answer() : ready_(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)) {
    if (ready_ < 0) throw std::system_error(errno, std::generic_category(), "agnocast: eventfd");
  }
  ~Answer() { ::close(ready_); }
  Answer(const Answer&) = delete;
  Answer& operator=(const Answer&) = delete;

  int ready_fd() const { return ready_; }

  void complete(std::optional<SchemaMessage> response, std::exception_ptr error) {
    {
      std::lock_guard lock(mutex_);
      if (response) response_.emplace(std::move(*response));
      error_ = error;
      done_ = true;
    }
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t written = ::write(ready_, &one, sizeof one);
  }
  bool done() const {
    std::lock_guard lock(mutex_);
    return done_;
  }
  // Once done(): the response, or the failure thrown.
  std::optional<SchemaMessage> take() {
    std::lock_guard lock(mutex_);
    if (error_) std::rethrow_exception(error_);
    return std::move(response_);
  }

 private:
  const int ready_;
  mutable std::mutex mutex_;
  bool done_ = false;
  std::optional<SchemaMessage> response_;
  std::exception_ptr error_;
};

int poll_milliseconds(std::chrono::nanoseconds remaining) {
  // Rounded up: a wait that ends a little early would only poll again at once.
  const auto ms = std::chrono::ceil<std::chrono::milliseconds>(remaining).count();
  return static_cast<int>(std::min<std::chrono::milliseconds::rep>(ms, 60'000));
}

}  // namespace

SchemaClient::SchemaClient(Node& node, std::string_view service, ServiceTypes types, const QoS& qos,
                           std::shared_ptr<CallbackGroup> group)
    : types_(std::move(types)) {
  require_native_layout(types_.request.schema.containers, types_.request.type_name,
                        "a service request built here");
  SubscriptionOptions options;
  options.callback_group = detail::group_or_default(*node.state(), std::move(group));
  core_ = std::make_shared<detail::ClientCore>(node.state(), service, qos,
                                               types_.request.message_type(),
                                               types_.response.message_type(), options);
  detail::register_waitable(*node.state(), core_);
}

SchemaClient::~SchemaClient() = default;

const std::string& SchemaClient::service_name() const { return core_->service_name(); }
bool SchemaClient::service_is_ready() const { return core_->service_is_ready(); }
bool SchemaClient::wait_for_service(std::chrono::nanoseconds timeout) const {
  return core_->wait_for_service(timeout);
}

RequestId SchemaClient::send(void* request, std::size_t bytes, Completion completion) {
  return core_->send(
      request, bytes,
      [completion = std::move(completion)](const void* response, detail::EntryReference* reference,
                                           std::exception_ptr error) {
        if (error) return completion(std::nullopt, error);
        completion(SchemaMessage(response, detail::pool_holding(response), reference), nullptr);
      });
}

RequestId SchemaClient::send_cdr(std::span<const std::uint8_t> cdr, Completion completion) {
  const detail::CdrLoan loan = detail::loan_from_cdr(types_.request.schema, cdr);
  return send(loan.message, loan.bytes, std::move(completion));
}

std::optional<SchemaMessage> SchemaClient::call(void* request, std::size_t bytes,
                                                std::chrono::nanoseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::shared_ptr<Answer> answer;
  try {
    answer = std::make_shared<Answer>();
  } catch (...) {
    detail::discard_message(request);
    throw;
  }
  const RequestId id = send(request, bytes, [answer](auto response, std::exception_ptr error) {
    answer->complete(std::move(response), error);
  });
  while (!answer->done()) {
    const auto remaining = deadline - std::chrono::steady_clock::now();
    // An answer being delivered right now is past the deadline as well.
    if (remaining <= std::chrono::nanoseconds::zero()) {
      forget(id);
      if (!answer->done()) return std::nullopt;
      break;
    }
    pollfd fds[] = {{core_->queue_fd(), POLLIN, 0}, {answer->ready_fd(), POLLIN, 0}};
    if (::poll(fds, 2, poll_milliseconds(remaining)) < 0 && errno != EINTR) {
      throw std::system_error(errno, std::generic_category(), "agnocast: poll");
    }
    if (fds[0].revents & POLLIN) core_->handle_wakeup();
  }
  return answer->take();
}

std::optional<SchemaMessage> SchemaClient::call_cdr(std::span<const std::uint8_t> cdr,
                                                    std::chrono::nanoseconds timeout) {
  const detail::CdrLoan loan = detail::loan_from_cdr(types_.request.schema, cdr);
  return call(loan.message, loan.bytes, timeout);
}

bool SchemaClient::forget(const RequestId& id) { return core_->forget(id); }
std::size_t SchemaClient::prune_pending() { return core_->prune_pending(); }
std::size_t SchemaClient::pending() const { return core_->pending(); }

}  // namespace agnocast
