#include "link/realtime.hpp"

#include <pthread.h>

#include <cstring>

namespace ecsim {

RealTimeThread::RealTimeThread(int priority) {
  (void)pthread_getschedparam(pthread_self(), &policy_, &saved_);
  sched_param p{};
  p.sched_priority = priority;
  const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
  ok_ = e == 0;
  note_ = ok_ ? "SCHED_FIFO " + std::to_string(priority)
              : "not real-time (" + std::string(std::strerror(e)) + ")";
}

RealTimeThread::~RealTimeThread() {
  if (ok_) (void)pthread_setschedparam(pthread_self(), policy_, &saved_);
}

}  // namespace ecsim
