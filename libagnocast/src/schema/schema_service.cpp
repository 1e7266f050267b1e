#include "agnocast/schema_service.hpp"

#include <cstring>
#include <utility>

#include "agnocast/detail/message.hpp"
#include "schema/cdr_to_pool.hpp"

namespace agnocast {

class SchemaService::Core : public detail::ServiceCore {
 public:
  Core(Node& node, std::string_view service, const ServiceTypes& types, const QoS& qos,
       Callback callback, const SubscriptionOptions& options)
      : ServiceCore(node.state(), service, qos, types.request.message_type(),
                    types.response.message_type(), empty_response(types.response.schema), options),
        callback_(std::move(callback)) {}

 private:
  // The word a stopping server sends carries no response: its clients read
  // the tag only, so zeros of the response's size do.
  static detail::ResponseFactory empty_response(const Schema& schema) {
    const std::size_t size = schema.types.at(0).size;
    const std::size_t align = detail::cdr_block_align(schema);
    return [size, align] {
      void* memory = detail::allocate_message(size, align, &detail::leave_to_block);
      std::memset(memory, 0, size);
      return memory;
    };
  }

  void handle_request(const void* request, detail::EntryReference* reference,
                      const RequestId& id) override {
    SchemaMessage held(request, detail::pool_holding(request), reference);
    callback_(std::move(held), id);
  }

  Callback callback_;
};

SchemaService::SchemaService(Node& node, std::string_view service, ServiceTypes types,
                             Callback callback, const QoS& qos,
                             std::shared_ptr<CallbackGroup> group)
    : types_(std::move(types)) {
  require_native_layout(types_.response.schema.containers, types_.response.type_name,
                        "a service response built here");
  SubscriptionOptions options;
  options.callback_group = detail::group_or_default(*node.state(), std::move(group));
  core_ = std::make_shared<Core>(node, service, types_, qos, std::move(callback), options);
  detail::register_waitable(*node.state(), core_);
}

SchemaService::~SchemaService() = default;

const std::string& SchemaService::service_name() const { return core_->service_name(); }

void SchemaService::send_response(const RequestId& id, void* response, std::size_t bytes) {
  core_->send_response(id, response, bytes);
}

void SchemaService::send_response_cdr(const RequestId& id, std::span<const std::uint8_t> cdr) {
  const detail::CdrLoan loan = detail::loan_from_cdr(types_.response.schema, cdr);
  send_response(id, loan.message, loan.bytes);
}

std::uint64_t SchemaService::calls() const { return core_->calls(); }
std::uint64_t SchemaService::failures() const { return core_->failures(); }

}  // namespace agnocast
