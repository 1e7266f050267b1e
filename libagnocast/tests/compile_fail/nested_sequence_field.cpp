// Must not compile: a sequence of sequences has no schema; the message says how to wrap it.
// expect: an array or sequence of sequences has no schema
// expect: wrap the inner agnocast::vector in a struct declared with AGNOCAST_MESSAGE
#include <agnocast/agnocast.hpp>

struct Rows {
  agnocast::vector<agnocast::vector<float>> rows;
};
AGNOCAST_MESSAGE(Rows, "rows/msg/Rows", rows);
