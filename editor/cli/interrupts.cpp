#include "cli/interrupts.hpp"

#include "stepwise/scene_io.hpp"

#include <csignal>

#include <unistd.h>

namespace stepwise::cli {

namespace {

volatile std::sig_atomic_t gCooperative = 0;
volatile std::sig_atomic_t gInterrupted = 0;

extern "C" void onInterrupt(int) {
    if (gCooperative) {
        gInterrupted = 1;
        return;
    }
    // Only async-signal-safe calls from here: unlink, write, _exit.
    removeUnfinishedTemporaries();
    static const char kMessage[] = "stepwise: error: interrupted; every output is as it was or complete\n";
    (void)!::write(2, kMessage, sizeof kMessage - 1);
    ::_exit(130);
}

void install(int signal) {
    struct sigaction old {};
    if (::sigaction(signal, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) return;
    struct sigaction action {};
    action.sa_handler = onInterrupt;
    sigemptyset(&action.sa_mask);
    ::sigaction(signal, &action, nullptr);
}

} // namespace

void installInterruptHandlers() {
    install(SIGINT);
    install(SIGTERM);
}

bool interruptRequested() { return gInterrupted != 0; }

CooperativeInterrupts::CooperativeInterrupts() {
    gInterrupted = 0;
    gCooperative = 1;
}

CooperativeInterrupts::~CooperativeInterrupts() { gCooperative = 0; }

} // namespace stepwise::cli
