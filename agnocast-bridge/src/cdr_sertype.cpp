#include "cdr_sertype.hpp"

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/q_radmin.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <new>

namespace agnocast_bridge {
namespace {

// What dds_write/dds_take would exchange if anyone used them on these topics;
// the bridge itself only uses dds_writecdr/dds_takecdr.
struct CdrSample {
  std::vector<std::uint8_t> bytes;
};

struct CdrSertype {
  ddsi_sertype base;  // first: Cyclone sees only this part
};

struct CdrSerdata {
  ddsi_serdata base;  // first: Cyclone sees only this part
  // The serialized sample, zero-padded to a multiple of 4 bytes: Cyclone reads
  // up to the next multiple of 4 beyond size.
  std::vector<std::uint8_t> bytes;
  std::uint32_t size = 0;
};

constexpr std::uint8_t keyless_key_bytes[4] = {0x00, 0x01, 0x00, 0x00};

CdrSerdata* as_cdr(ddsi_serdata* serdata) { return reinterpret_cast<CdrSerdata*>(serdata); }
const CdrSerdata* as_cdr(const ddsi_serdata* serdata) {
  return reinterpret_cast<const CdrSerdata*>(serdata);
}

CdrSerdata* new_serdata(const ddsi_sertype* type, ddsi_serdata_kind kind,
                        std::vector<std::uint8_t>&& bytes) {
  auto* data = new (std::nothrow) CdrSerdata();
  if (data == nullptr) return nullptr;
  ddsi_serdata_init(&data->base, type, kind);
  data->base.hash = type != nullptr ? type->serdata_basehash : 0;  // keyless: one instance
  data->size = static_cast<std::uint32_t>(bytes.size());
  data->bytes = std::move(bytes);
  data->bytes.resize((data->bytes.size() + 3) / 4 * 4, 0);
  return data;
}

std::vector<std::uint8_t> key_bytes() {
  return {std::begin(keyless_key_bytes), std::end(keyless_key_bytes)};
}

// --- serdata operations

bool serdata_eqkey(const ddsi_serdata*, const ddsi_serdata*) { return true; }  // keyless

uint32_t serdata_size(const ddsi_serdata* serdata) { return as_cdr(serdata)->size; }

void serdata_free(ddsi_serdata* serdata) { delete as_cdr(serdata); }

ddsi_serdata* serdata_from_ser(const ddsi_sertype* type, ddsi_serdata_kind kind,
                               const nn_rdata* fragment, size_t size) {
  std::vector<std::uint8_t> bytes(size);
  // Fragments arrive in order of their offsets and may overlap: copy what is new.
  std::uint32_t copied = 0;
  for (; fragment != nullptr && copied < size; fragment = fragment->nextfrag) {
    if (fragment->maxp1 <= copied) continue;
    const unsigned char* payload =
        NN_RMSG_PAYLOADOFF(fragment->rmsg, NN_RDATA_PAYLOAD_OFF(fragment));
    const std::uint32_t end =
        std::min<std::uint32_t>(fragment->maxp1, static_cast<std::uint32_t>(size));
    std::memcpy(bytes.data() + copied, payload + (copied - fragment->min), end - copied);
    copied = end;
  }
  auto* data = new_serdata(type, kind, std::move(bytes));
  return data != nullptr ? &data->base : nullptr;
}

ddsi_serdata* serdata_from_ser_iov(const ddsi_sertype* type, ddsi_serdata_kind kind,
                                   ddsrt_msg_iovlen_t count, const ddsrt_iovec_t* iov,
                                   size_t size) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(size);
  for (ddsrt_msg_iovlen_t i = 0; i < count && bytes.size() < size; ++i) {
    const auto* base = static_cast<const std::uint8_t*>(iov[i].iov_base);
    const std::size_t take = std::min<std::size_t>(iov[i].iov_len, size - bytes.size());
    bytes.insert(bytes.end(), base, base + take);
  }
  auto* data = new_serdata(type, kind, std::move(bytes));
  return data != nullptr ? &data->base : nullptr;
}

ddsi_serdata* serdata_from_keyhash(const ddsi_sertype* type, const ddsi_keyhash*) {
  auto* data = new_serdata(type, SDK_KEY, key_bytes());
  return data != nullptr ? &data->base : nullptr;
}

ddsi_serdata* serdata_from_sample(const ddsi_sertype* type, ddsi_serdata_kind kind,
                                  const void* sample) {
  std::vector<std::uint8_t> bytes =
      kind == SDK_KEY ? key_bytes() : static_cast<const CdrSample*>(sample)->bytes;
  auto* data = new_serdata(type, kind, std::move(bytes));
  return data != nullptr ? &data->base : nullptr;
}

void serdata_to_ser(const ddsi_serdata* serdata, size_t offset, size_t size, void* buffer) {
  std::memcpy(buffer, as_cdr(serdata)->bytes.data() + offset, size);
}

ddsi_serdata* serdata_to_ser_ref(const ddsi_serdata* serdata, size_t offset, size_t size,
                                 ddsrt_iovec_t* reference) {
  reference->iov_base = const_cast<std::uint8_t*>(as_cdr(serdata)->bytes.data() + offset);
  reference->iov_len = static_cast<ddsrt_iov_len_t>(size);
  return ddsi_serdata_ref(serdata);
}

void serdata_to_ser_unref(ddsi_serdata* serdata, const ddsrt_iovec_t*) {
  ddsi_serdata_unref(serdata);
}

bool serdata_to_sample(const ddsi_serdata* serdata, void* sample, void**, void*) {
  const CdrSerdata* data = as_cdr(serdata);
  static_cast<CdrSample*>(sample)->bytes.assign(data->bytes.begin(),
                                                data->bytes.begin() + data->size);
  return true;
}

ddsi_serdata* serdata_to_untyped(const ddsi_serdata* serdata) {
  auto* data = new_serdata(serdata->type, SDK_KEY, key_bytes());
  if (data == nullptr) return nullptr;
  data->base.type = nullptr;  // untyped, as Cyclone expects of this operation
  return &data->base;
}

bool serdata_untyped_to_sample(const ddsi_sertype*, const ddsi_serdata*, void* sample, void**,
                               void*) {
  static_cast<CdrSample*>(sample)->bytes.clear();
  return true;
}

size_t serdata_print(const ddsi_sertype*, const ddsi_serdata* serdata, char* buffer, size_t size) {
  const int written = std::snprintf(buffer, size, "xcdr1(%u bytes)", as_cdr(serdata)->size);
  return written < 0 ? 0 : static_cast<size_t>(written);
}

void serdata_get_keyhash(const ddsi_serdata*, ddsi_keyhash* keyhash, bool) {
  std::memset(keyhash->value, 0, sizeof(keyhash->value));
}

const ddsi_serdata_ops cdr_serdata_ops = {
    .eqkey = serdata_eqkey,
    .get_size = serdata_size,
    .from_ser = serdata_from_ser,
    .from_ser_iov = serdata_from_ser_iov,
    .from_keyhash = serdata_from_keyhash,
    .from_sample = serdata_from_sample,
    .to_ser = serdata_to_ser,
    .to_ser_ref = serdata_to_ser_ref,
    .to_ser_unref = serdata_to_ser_unref,
    .to_sample = serdata_to_sample,
    .to_untyped = serdata_to_untyped,
    .untyped_to_sample = serdata_untyped_to_sample,
    .free = serdata_free,
    .print = serdata_print,
    .get_keyhash = serdata_get_keyhash,
#ifdef DDS_HAS_SHM
    .get_sample_size = nullptr,  // no iceoryx: the bridge's Cyclone runs without SHM
    .from_iox_buffer = nullptr,
#endif
};

// --- sertype operations

void sertype_free(ddsi_sertype* type) {
  ddsi_sertype_fini(type);
  delete reinterpret_cast<CdrSertype*>(type);
}

void sertype_zero_samples(const ddsi_sertype*, void* samples, size_t count) {
  auto* sample = static_cast<CdrSample*>(samples);
  for (size_t i = 0; i < count; ++i) sample[i].bytes.clear();
}

void sertype_realloc_samples(void** pointers, const ddsi_sertype*, void* old, size_t old_count,
                             size_t count) {
  auto* grown = new CdrSample[count];
  auto* previous = static_cast<CdrSample*>(old);
  for (size_t i = 0; i < std::min(old_count, count); ++i) grown[i] = std::move(previous[i]);
  delete[] previous;
  for (size_t i = 0; i < count; ++i) pointers[i] = &grown[i];
}

void sertype_free_samples(const ddsi_sertype*, void** pointers, size_t count, dds_free_op_t op) {
  if (count == 0) return;
  if (op & DDS_FREE_CONTENTS_BIT) {
    for (size_t i = 0; i < count; ++i) static_cast<CdrSample*>(pointers[i])->bytes.clear();
  }
  if (op & DDS_FREE_ALL_BIT) delete[] static_cast<CdrSample*>(pointers[0]);
}

// Cyclone has compared name, key kind and operations already: nothing else differs.
bool sertype_equal(const ddsi_sertype*, const ddsi_sertype*) { return true; }
uint32_t sertype_hash(const ddsi_sertype*) { return 0; }

size_t sertype_serialized_size(const ddsi_sertype*, const void* sample) {
  return static_cast<const CdrSample*>(sample)->bytes.size();
}

bool sertype_serialize_into(const ddsi_sertype*, const void* sample, void* buffer, size_t size) {
  const auto& bytes = static_cast<const CdrSample*>(sample)->bytes;
  if (bytes.size() > size) return false;
  std::memcpy(buffer, bytes.data(), bytes.size());
  return true;
}

const ddsi_sertype_ops cdr_sertype_ops = {
    .version = ddsi_sertype_v0,
    .arg = nullptr,
    .free = sertype_free,
    .zero_samples = sertype_zero_samples,
    .realloc_samples = sertype_realloc_samples,
    .free_samples = sertype_free_samples,
    .equal = sertype_equal,
    .hash = sertype_hash,
    // No XTypes type information: peers match on the type name, as ROS 2 nodes do.
    .type_id = nullptr,
    .type_map = nullptr,
    .type_info = nullptr,
    .derive_sertype = nullptr,
    .get_serialized_size = sertype_serialized_size,
    .serialize_into = sertype_serialize_into,
};

}  // namespace

ddsi_sertype* make_cdr_sertype(const std::string& dds_type_name) {
  auto* type = new CdrSertype();
  ddsi_sertype_init_flags(&type->base, dds_type_name.c_str(), &cdr_sertype_ops, &cdr_serdata_ops,
                          DDSI_SERTYPE_FLAG_TOPICKIND_NO_KEY);
  return &type->base;
}

ddsi_serdata* make_cdr_serdata(const ddsi_sertype* type, std::vector<std::uint8_t>&& bytes) {
  // XCDR pads a sample to a multiple of 4 bytes and says how much it padded in
  // the last two bits of the encapsulation options, as Cyclone's own writers do.
  const std::size_t padding = (4 - bytes.size() % 4) % 4;
  if (bytes.size() >= 4) {
    bytes.resize(bytes.size() + padding, 0);
    bytes[3] = static_cast<std::uint8_t>((bytes[3] & ~0x3u) | padding);
  }
  CdrSerdata* data = new_serdata(type, SDK_DATA, std::move(bytes));
  if (data == nullptr) throw std::bad_alloc();
  return &data->base;
}

std::span<const std::uint8_t> cdr_serdata_bytes(const ddsi_serdata* serdata) {
  const CdrSerdata* data = as_cdr(serdata);
  return {data->bytes.data(), data->size};
}

void release_serdata(ddsi_serdata* serdata) { ddsi_serdata_unref(serdata); }

}  // namespace agnocast_bridge
