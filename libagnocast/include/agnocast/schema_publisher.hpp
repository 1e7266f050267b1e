// A publisher for tools that hold messages as CDR and know their type only
// from a schema (agnocast-cli bag play, agnocast-foxglove's clientPublish):
// it publishes with the type name, layout hash and schema that a compiled
// subscriber of the topic expects, and turns each message's XCDR1 bytes back
// into the message in one pool block (the message, then the elements of its
// sequences and the characters of its long strings), so the block's release
// frees everything.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "agnocast/node.hpp"
#include "agnocast/qos.hpp"
#include "agnocast/schema.hpp"

namespace agnocast {

namespace detail {
class PublisherCore;
}

class SchemaPublisher {
 public:
  // blob: the schema as the kernel holds it (topic_schema(), or what bag
  // record stored). Throws SchemaError for an invalid blob or containers laid
  // out otherwise than this process writes them (libstdc++ on a 64-bit
  // machine), and what creating a publisher throws (TypeMismatch, AccessDenied, ...).
  SchemaPublisher(Node& node, std::string_view topic, const QoS& qos, std::string type_name,
                  std::uint64_t type_hash, std::vector<std::uint8_t> blob);
  ~SchemaPublisher();
  SchemaPublisher(const SchemaPublisher&) = delete;
  SchemaPublisher& operator=(const SchemaPublisher&) = delete;

  const Schema& schema() const { return schema_; }
  const std::string& type_name() const { return type_name_; }
  const std::string& topic() const;

  // Publishes the message whose little-endian XCDR1 bytes, encapsulation
  // header included, are `cdr`. Throws cdr::Error, naming the field, when they
  // are not a message of the type; nothing is published then.
  void publish_cdr(std::span<const std::uint8_t> cdr);

 private:
  std::string type_name_;
  std::vector<std::uint8_t> blob_;
  Schema schema_;
  std::unique_ptr<detail::PublisherCore> core_;
};

}  // namespace agnocast
