#include "agnocast/schema_service.hpp"

#include <cstring>
#include <utility>

#include "agnocast/detail/message.hpp"
#include "schema/cdr_to_pool.hpp"

namespace agnocast {

class SchemaService::Core : public detail::ServiceCore,
                            public std::enable_shared_from_this<SchemaService::Core> {
 public:
  Core(Node& node, std::string_view service, ServiceTypes types, const QoS& qos, Callback callback,
       const SubscriptionOptions& options)
      : ServiceCore(node.state(), service, qos, types.request.message_type(),
                    types.response.message_type(), empty_response(types.response.schema), options),
        types_(std::move(types)),
        callback_(std::move(callback)) {}

  const ServiceTypes& types() const { return types_; }

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
    callback_(std::move(held), Responder(shared_from_this(), id));
  }

  const ServiceTypes types_;
  Callback callback_;
};

void SchemaService::Responder::send(void* response, std::size_t bytes) const {
  core_->send_response(id_, response, bytes);
}

void SchemaService::Responder::send_cdr(std::span<const std::uint8_t> cdr) const {
  const detail::CdrLoan loan = detail::loan_from_cdr(core_->types().response.schema, cdr);
  send(loan.message, loan.bytes);
}

SchemaService::SchemaService(Node& node, std::string_view service, ServiceTypes types,
                             Callback callback, const QoS& qos,
                             std::shared_ptr<CallbackGroup> group) {
  require_native_layout(types.response.schema.containers, types.response.type_name,
                        "a service response built here");
  SubscriptionOptions options;
  options.callback_group = detail::group_or_default(*node.state(), std::move(group));
  core_ =
      std::make_shared<Core>(node, service, std::move(types), qos, std::move(callback), options);
  detail::register_waitable(*node.state(), core_);
}

SchemaService::~SchemaService() = default;

const ServiceTypes& SchemaService::types() const { return core_->types(); }
const std::string& SchemaService::service_name() const { return core_->service_name(); }
std::uint64_t SchemaService::calls() const { return core_->calls(); }
std::uint64_t SchemaService::failures() const { return core_->failures(); }

}  // namespace agnocast
