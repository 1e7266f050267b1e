// A Cyclone DDS type whose samples are finished XCDR1 bytes (encapsulation
// header included), as agnocast::cdr::serialize() writes them: the bridge
// serializes each message once with the generated code and hands the bytes to
// Cyclone as they are (dds_writecdr), and reads what arrives as bytes
// (dds_takecdr) to deserialize straight into a loaned agnocast message.
// One implementation serves every message type: only the type name differs.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

struct ddsi_sertype;
struct ddsi_serdata;

namespace agnocast_bridge {

// A keyless sertype named dds_type_name ("pkg::msg::dds_::Type_"), for
// dds_create_topic_sertype, which takes ownership of it.
ddsi_sertype* make_cdr_sertype(const std::string& dds_type_name);

// A serdata holding bytes (encapsulation header first), padded to a multiple of
// 4 with the padding noted in the header's options as XCDR says; refcount 1,
// for dds_writecdr, which consumes that reference.
ddsi_serdata* make_cdr_serdata(const ddsi_sertype* type, std::vector<std::uint8_t>&& bytes);

// The bytes of a serdata of a cdr sertype (from dds_takecdr), header included.
std::span<const std::uint8_t> cdr_serdata_bytes(const ddsi_serdata* serdata);

// Drops a reference to a serdata (one dds_takecdr handed out).
void release_serdata(ddsi_serdata* serdata);

}  // namespace agnocast_bridge
