// SignalFlag: turns SIGINT/SIGTERM into a flag that a main loop polls, so that a tool can
// stop, flush its capture file and close its links normally instead of dying mid-write.
//
//   SignalFlag stop;                        // installs the handlers
//   while (!stop.raised()) { link.receive(buf, 10ms); ... }
//   writer.close();                         // flushed and complete
//
// Global state: a signal handler can reach no object, so the handler writes one lock-free
// std::atomic<int> at file scope in signal_flag.cpp (the number of the signal caught). It is
// the only process-wide mutable state in link/. Hence only one SignalFlag should be alive at
// a time; its destructor restores the handlers that were installed before it.
//
// The handlers are installed without SA_RESTART, so a blocking wait in Link::receive() ends
// early (returning 0) and the loop sees the flag at once. They use SA_RESETHAND: a second
// signal of the same kind takes the default action, so a hung program can still be stopped.
#pragma once

#include <csignal>
#include <initializer_list>
#include <vector>

namespace ecsim {

class SignalFlag {
 public:
  SignalFlag() : SignalFlag({SIGINT, SIGTERM}) {}
  explicit SignalFlag(std::initializer_list<int> signals);
  ~SignalFlag();
  SignalFlag(const SignalFlag&) = delete;
  SignalFlag& operator=(const SignalFlag&) = delete;

  bool raised() const { return signal() != 0; }
  // The last signal caught, 0 when none.
  int signal() const;
  // Forgets a caught signal (the handler stays reset to the default after one signal).
  void clear();

 private:
  struct Saved {
    int number;
    struct sigaction previous;
  };
  std::vector<Saved> saved_;
};

}  // namespace ecsim
