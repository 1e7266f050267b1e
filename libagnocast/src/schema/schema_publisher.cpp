#include "agnocast/schema_publisher.hpp"

#include <utility>

#include "agnocast/detail/endpoints.hpp"
#include "schema/cdr_to_pool.hpp"

namespace agnocast {

SchemaPublisher::SchemaPublisher(Node& node, std::string_view topic, const QoS& qos,
                                 std::string type_name, std::uint64_t type_hash,
                                 std::vector<std::uint8_t> blob)
    : type_name_(std::move(type_name)), blob_(std::move(blob)), schema_(parse_schema(blob_)) {
  require_native_layout(schema_.containers, type_name_, "a message written from CDR");
  core_ = std::make_unique<detail::PublisherCore>(
      node.state(), topic, qos, detail::MessageType{type_name_, type_hash, blob_});
}

SchemaPublisher::~SchemaPublisher() = default;

const std::string& SchemaPublisher::topic() const { return core_->topic(); }

void SchemaPublisher::publish_cdr(std::span<const std::uint8_t> cdr) {
  const detail::CdrLoan loan = detail::loan_from_cdr(schema_, cdr);
  core_->publish(loan.message, loan.bytes);
}

}  // namespace agnocast
