// Must not compile: a message declared with AGNOCAST_MESSAGE is filled outside
// any loan scope, so it cannot hold a heap message (whose std members would
// then point into the publisher's private heap).
// expect: can be a field of another AGNOCAST_HEAP_MESSAGE only
#include <agnocast/agnocast.hpp>
#include <string>

struct Label {
  std::string text;
};
AGNOCAST_HEAP_MESSAGE(Label, "labels/msg/Label", text);

struct Labels {
  agnocast::vector<Label> labels;
};
AGNOCAST_MESSAGE(Labels, "labels/msg/Labels", labels);
