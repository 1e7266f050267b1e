#pragma once

namespace agnocast::detail {

// Readable (level-triggered, never drained) once SIGINT or SIGTERM arrived.
int shutdown_eventfd();

}  // namespace agnocast::detail
