// The CLI's handling of fatal signals (signal_cleanup.cpp).
#pragma once

namespace fiblet::cli {

// Installs handlers for every catchable signal that ends a process by
// default (fiblet::fatal_signals(): SIGINT, SIGTERM, SIGHUP, SIGQUIT,
// SIGPIPE, SIGXFSZ, SIGXCPU, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF)
// that remove pending outputs, print which signal stopped the process (not
// for SIGINT or SIGPIPE) and exit with 128 + signal (the shell convention).
// Signals the parent ignored stay ignored.
void install_signal_cleanup();

}  // namespace fiblet::cli
