#pragma once
// Ctrl-C (SIGINT) and SIGTERM, at any moment, end a command with exit 130,
// every output either as it was or complete and no temporary left behind.
// A step loop takes them cooperatively (it stops at the next step and says
// where); anywhere else the handler removes the unfinished temporaries and
// exits at once. A signal ignored when the program started stays ignored.

namespace stepwise::cli {

/// Installs the handlers; main() calls it first.
void installInterruptHandlers();

/// True once an interrupt arrived inside a CooperativeInterrupts scope.
bool interruptRequested();

/// While one is alive, an interrupt only sets interruptRequested().
class CooperativeInterrupts {
public:
    CooperativeInterrupts();
    ~CooperativeInterrupts();
    CooperativeInterrupts(const CooperativeInterrupts&) = delete;
    CooperativeInterrupts& operator=(const CooperativeInterrupts&) = delete;
};

} // namespace stepwise::cli
