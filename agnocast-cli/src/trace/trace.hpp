// agnocast-cli trace record | report.
#pragma once

#include "cli.hpp"

namespace agnocast::cli {

void set_trace_command(CLI::App& app, Context& context);

}  // namespace agnocast::cli
