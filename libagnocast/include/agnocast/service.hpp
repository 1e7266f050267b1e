// Request and response between processes, zero-copy both ways: a client
// borrows a request from its own pool, the server reads it in place and
// fills a response borrowed from its pool, which the client reads in place.
// Node::create_service() and Node::create_client() make them.
#pragma once

#include <chrono>
#include <functional>
#include <future>
#include <memory>
#include <type_traits>
#include <utility>

#include "agnocast/detail/loan.hpp"
#include "agnocast/detail/service_cores.hpp"
#include "agnocast/errors.hpp"
#include "agnocast/heap_scope.hpp"
#include "agnocast/ipc_shared_ptr.hpp"
#include "agnocast/limits.hpp"
#include "agnocast/service_traits.hpp"

namespace agnocast {

// A server's request queue unless its QoS says otherwise: requests are never
// dropped, so the depth only says when to refuse more.
inline constexpr std::size_t service_queue_depth_default = qos_depth_max;
// A client's requests in flight unless its QoS says otherwise.
inline constexpr std::size_t client_in_flight_default = 10;

namespace detail {

template <class T>
void* borrow_empty_loan() {
  T* message = borrow_loan<T>();
  close_loan_heap_scope(message);
  return message;
}

}  // namespace detail

// Answers the requests of a service name; one per name in the IPC namespace.
// Destroying it tells every client that what it has not had answered never will be.
template <ServiceType Srv>
class Service : public detail::ServiceCore, public std::enable_shared_from_this<Service<Srv>> {
 public:
  using Request = typename Srv::Request;
  using Response = typename Srv::Response;
  // Fills the response it is handed; it is sent when the callback returns.
  using Callback =
      std::function<void(const ipc_shared_ptr<const Request>&, ipc_shared_ptr<Response>&)>;
  // Keeps the request and answers later with send_response().
  using DeferredCallback =
      std::function<void(std::shared_ptr<Service<Srv>>, RequestId, ipc_shared_ptr<const Request>)>;

  Service(std::shared_ptr<detail::NodeState> node, std::string_view name, const QoS& qos,
          Callback callback, const SubscriptionOptions& options)
      : ServiceCore(std::move(node), name, qos, detail::message_type_of<Request>(),
                    detail::message_type_of<Response>(), &detail::borrow_empty_loan<Response>,
                    options),
        callback_(std::move(callback)) {}
  Service(std::shared_ptr<detail::NodeState> node, std::string_view name, const QoS& qos,
          DeferredCallback callback, const SubscriptionOptions& options)
      : ServiceCore(std::move(node), name, qos, detail::message_type_of<Request>(),
                    detail::message_type_of<Response>(), &detail::borrow_empty_loan<Response>,
                    options),
        deferred_(std::move(callback)) {}

  // A default-constructed response in this process's pool.
  ipc_shared_ptr<Response> borrow_loaned_response() {
    return detail::MessageAccess::loan(detail::borrow_loan<Response>());
  }
  // Sends the response to the client whose request id names; response is
  // empty afterwards. A client that is gone does not get it (no error).
  void send_response(const RequestId& id, ipc_shared_ptr<Response>&& response) {
    Response* loaned = detail::loan_to_send(
        response, "send_response needs a response from borrow_loaned_response() not yet sent");
    detail::close_loan_heap_scope(loaned);
    ServiceCore::send_response(id, loaned, detail::published_bytes(loaned, sizeof(Response)));
  }

  // Answers the request with a failure instead of a response: the client's
  // future throws ServiceUnavailable. For a server that cannot answer (a
  // bridge whose far side did not in time).
  void fail_request(const RequestId& id) { ServiceCore::fail_request(id); }

  const std::string& get_service_name() const { return service_name(); }

 private:
  void handle_request(const void* request, detail::EntryReference* reference,
                      const RequestId& id) override {
    auto pointer = detail::MessageAccess::received(static_cast<const Request*>(request), reference);
    if (deferred_) {
      deferred_(this->shared_from_this(), id, std::move(pointer));
      return;
    }
    auto response = borrow_loaned_response();
    callback_(pointer, response);
    if (response) send_response(id, std::move(response));
  }

  Callback callback_;
  DeferredCallback deferred_;
};

// Calls a service: requests go to its one server, each answer comes back to
// this client alone, through the executor that spins the client's node.
template <ServiceType Srv>
class Client : public detail::ClientCore {
 public:
  using Request = typename Srv::Request;
  using Response = typename Srv::Response;
  using SharedFuture = std::shared_future<ipc_shared_ptr<const Response>>;

  Client(std::shared_ptr<detail::NodeState> node, std::string_view name, const QoS& qos,
         const SubscriptionOptions& options)
      : ClientCore(std::move(node), name, qos, detail::message_type_of<Request>(),
                   detail::message_type_of<Response>(), options) {}

  // A default-constructed request in this process's pool.
  ipc_shared_ptr<Request> borrow_loaned_request() {
    return detail::MessageAccess::loan(detail::borrow_loan<Request>());
  }

  // Sends the request (empty afterwards). The future holds the response, or
  // throws ServiceUnavailable (no server, or it went away before answering)
  // or RequestRejected (its queue was full). Throws TooManyRequests, with
  // nothing sent, when the client's QoS depth of requests is in flight.
  SharedFuture async_send_request(ipc_shared_ptr<Request>&& request) {
    return async_send_request(std::move(request), nullptr);
  }
  // The same; callback(future) runs once the future is ready.
  SharedFuture async_send_request(ipc_shared_ptr<Request>&& request,
                                  std::function<void(SharedFuture)> callback) {
    Request* loaned = detail::loan_to_send(
        request, "async_send_request needs a request from borrow_loaned_request() not yet sent");
    detail::close_loan_heap_scope(loaned);
    std::unique_ptr<Call> call;
    try {
      call = std::make_unique<Call>(std::move(callback));
    } catch (...) {
      detail::discard_message(loaned);
      throw;
    }
    SharedFuture future = call->future;
    send(loaned, detail::published_bytes(loaned, sizeof(Request)), std::move(call));
    return future;
  }

  template <class Rep, class Period>
  bool wait_for_service(std::chrono::duration<Rep, Period> timeout) const {
    return ClientCore::wait_for_service(
        std::chrono::duration_cast<std::chrono::nanoseconds>(timeout));
  }
  bool service_is_ready() const { return ClientCore::service_is_ready(); }
  // Forgets every pending request: their futures are abandoned (broken_promise).
  std::size_t prune_pending_requests() { return prune_pending(); }
  const std::string& get_service_name() const { return service_name(); }

 private:
  // The promise, its future and the callback in one allocation.
  struct Call final : detail::PendingCall {
    explicit Call(std::function<void(SharedFuture)> on_ready)
        : future(promise.get_future().share()), callback(std::move(on_ready)) {}
    void complete(const void* response, detail::EntryReference* reference,
                  std::exception_ptr error) override {
      if (error) {
        promise.set_exception(std::move(error));
      } else {
        promise.set_value(
            detail::MessageAccess::received(static_cast<const Response*>(response), reference));
      }
      if (callback) callback(future);
    }

    std::promise<ipc_shared_ptr<const Response>> promise;
    SharedFuture future;
    std::function<void(SharedFuture)> callback;
  };
};

}  // namespace agnocast
