// Must not compile: AGNOCAST_MESSAGE refuses a field that is a std::vector.
#include <agnocast/agnocast.hpp>
#include <vector>

struct Samples {
  double rate;
  std::vector<float> values;
};
AGNOCAST_MESSAGE(Samples, "samples/msg/Samples", rate, values);
