#include "agnocast/supervise.hpp"

#include <unistd.h>

#include "kernel/device.hpp"

namespace agnocast {

ExitRecordReader::ExitRecordReader() : fd_(detail::Device::open(/*nonblocking=*/true).release()) {}

ExitRecordReader::~ExitRecordReader() { ::close(fd_); }

std::vector<ExitRecord> ExitRecordReader::read_available() {
  detail::Device device(fd_);
  struct GiveBack {
    detail::Device& device;
    ~GiveBack() { device.release(); }
  } give_back{device};
  return device.read_exit_records();
}

}  // namespace agnocast
