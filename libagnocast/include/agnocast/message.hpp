// Everything a generated message header needs: containers, traits and XCDR1.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "agnocast/allocator.hpp"
#include "agnocast/cdr.hpp"
#include "agnocast/message_traits.hpp"
