// KernelThreadSender: sends on a socket without a system call on the caller's CPU. The frames
// go through an io_uring (io_uring(7), io_uring_setup(2)) whose submission queue a kernel
// thread polls (IORING_SETUP_SQPOLL), pinned to another CPU: a send is a few stores into
// memory shared with that thread, which makes the send() for us.
//
// Why (docs/served-path.md): on a kernel with page-table isolation and no PCID, as
// on this project's CI machines, every entry into the kernel empties the TLB, and the next
// frame through a long line of simulated slaves pays for it: 48 ns per slave after a getppid()
// against 30 ns without, at 1000 slaves. A busy-polling server (`ecsim serve --busy-poll`)
// that receives through a ring (link/packet_rx_ring.hpp) and sends through this one never
// enters the kernel between two frames.
//
// send() waits for its own completion (spinning, then sleeping in io_uring_enter), so it
// returns the send's own result as a plain send(2) would, frames leave in the order given and
// the caller's bytes need to live only for the call. The kernel thread spins while frames
// come and sleeps after `idleMs` without one; the next send then wakes it (one system call).
// Written against the kernel's ABI (<linux/io_uring.h>), without liburing.
#pragma once

#include <cstdint>
#include <string>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"
#include "protocol/unique_fd.hpp"

struct io_uring_sqe;
struct io_uring_cqe;

namespace ecsim {

class KernelThreadSender {
 public:
  // An io_uring on `socket` (not owned: it must outlive the sender) with its polling thread on
  // `cpu`. `where` names the socket in errors. Errors: kUnsupported when the kernel refuses an
  // io_uring (too old, io_uring_disabled, a seccomp filter), kInvalidArgument for a CPU that is
  // not online or not allowed, kIo otherwise.
  static Result<KernelThreadSender> open(int socket, int cpu, const std::string& where,
                                         unsigned idleMs = 1000);

  KernelThreadSender(KernelThreadSender&& other) noexcept;
  KernelThreadSender& operator=(KernelThreadSender&& other) noexcept;
  KernelThreadSender(const KernelThreadSender&) = delete;
  KernelThreadSender& operator=(const KernelThreadSender&) = delete;
  ~KernelThreadSender();

  // Sends `frame` as one send(2) with no flags and returns when the kernel has done it: what
  // send(2) would have returned, the bytes sent or minus the errno it failed with. An error
  // only when the io_uring itself failed.
  Result<long> send(ConstBytes frame);

  int cpu() const { return cpu_; }
  // Sends that found the polling thread asleep and had to wake it (a system call each).
  std::uint64_t wakeUps() const { return wakeUps_; }

 private:
  KernelThreadSender() = default;
  void release();
  // The next completion's result, waiting for it.
  Result<long> awaitCompletion();

  UniqueFd ring_;
  int cpu_{-1};
  std::string where_;
  // The two rings and the entries, mapped from ring_.
  void* sqMap_{nullptr};
  std::size_t sqMapBytes_{0};
  void* cqMap_{nullptr};  // == sqMap_ with IORING_FEAT_SINGLE_MMAP
  std::size_t cqMapBytes_{0};
  io_uring_sqe* sqes_{nullptr};
  std::size_t sqesBytes_{0};
  // Fields inside the maps (io_uring_params::sq_off and cq_off).
  unsigned* sqTail_{nullptr};
  unsigned* sqFlags_{nullptr};
  unsigned* sqArray_{nullptr};
  unsigned sqMask_{0};
  unsigned* cqHead_{nullptr};
  unsigned* cqTail_{nullptr};
  unsigned cqMask_{0};
  io_uring_cqe* cqes_{nullptr};
  std::uint64_t wakeUps_{0};
};

}  // namespace ecsim
