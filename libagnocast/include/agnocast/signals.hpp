#pragma once

namespace agnocast {

// Installs SIGINT/SIGTERM handlers that make every executor's spin() return
// and ok() false; a handler installed before is still called. Executors call
// this themselves; programs with their own loop may call it and poll ok().
void install_signal_handlers();
// False once SIGINT or SIGTERM arrived after install_signal_handlers().
bool ok();

}  // namespace agnocast
