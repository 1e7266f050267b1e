// What makes seed::Msg an agnocast message, beside its unmodified header.
#pragma once

#include <agnocast/message_traits.hpp>

#include "seed_message.hpp"

AGNOCAST_HEAP_MESSAGE(seed::Tag, "seed/msg/Tag", key, values);
AGNOCAST_HEAP_MESSAGE(seed::Msg, "seed/msg/Msg", seq, payload, frame_id, points, tags);
