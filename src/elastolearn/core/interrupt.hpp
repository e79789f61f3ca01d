#pragma once
/// \file Cooperative interruption (Ctrl-C): the app installs a handler that only sets a flag;
/// long loops poll it and stop cleanly, so outputs are finalised or removed, never half-written.
namespace elastolearn {

/// Install SIGINT/SIGTERM handlers that set the interrupt flag (a second signal kills at once).
void install_interrupt_handler();
/// True once an interrupt was requested.
bool interrupt_requested();
/// Set or clear the flag (tests, or a caller that handled it).
void set_interrupt_requested(bool value);

} // namespace elastolearn
