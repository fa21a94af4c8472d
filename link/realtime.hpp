// SCHED_FIFO for the calling thread while an object lives: the thread that runs a master or
// answers one over a real link, so that a loaded host does not turn into lost frames
// (developers' guide: third-party masters run with real-time priority where permitted). Without
// root or CAP_SYS_NICE the thread keeps its policy and note() says why.
#pragma once

#include <sched.h>

#include <string>

namespace ecsim {

class RealTimeThread {
 public:
  explicit RealTimeThread(int priority);
  ~RealTimeThread();
  RealTimeThread(const RealTimeThread&) = delete;
  RealTimeThread& operator=(const RealTimeThread&) = delete;

  bool ok() const { return ok_; }
  // "SCHED_FIFO 50", or "not real-time (Operation not permitted)".
  const std::string& note() const { return note_; }

 private:
  int policy_{SCHED_OTHER};
  sched_param saved_{};
  bool ok_{false};
  std::string note_;
};

}  // namespace ecsim
