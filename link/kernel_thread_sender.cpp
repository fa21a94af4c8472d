#include "link/kernel_thread_sender.hpp"

#include <linux/io_uring.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>

namespace ecsim {
namespace {

// One frame is in flight at a time (send() waits for it); a few entries to spare.
constexpr unsigned kEntries = 4;
// send() spins this long for its completion before it sleeps in the kernel (which also lets a
// polling thread that shares our CPU run).
constexpr auto kSpinBeforeSleeping = std::chrono::microseconds(200);
// The socket is the ring's registered file 0.
constexpr int kFixedSocket = 0;

int ioUringSetup(unsigned entries, io_uring_params* p) {
  return static_cast<int>(::syscall(__NR_io_uring_setup, entries, p));
}
int ioUringEnter(int ring, unsigned submit, unsigned minComplete, unsigned flags) {
  return static_cast<int>(
      ::syscall(__NR_io_uring_enter, ring, submit, minComplete, flags, nullptr, 0));
}
int ioUringRegister(int ring, unsigned opcode, const void* arg, unsigned count) {
  return static_cast<int>(::syscall(__NR_io_uring_register, ring, opcode, arg, count));
}

void* mapRing(int ring, std::size_t bytes, off_t offset) {
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_POPULATE, ring, offset);
  return p == MAP_FAILED ? nullptr : p;
}

template <typename T>
T* field(void* map, unsigned offset) {
  return reinterpret_cast<T*>(static_cast<char*>(map) + offset);
}

// Whether the kernel knows IORING_OP_SEND (Linux 5.6): asked once, at open().
bool sendSupported(int ring) {
  alignas(io_uring_probe)
      std::array<std::uint8_t, sizeof(io_uring_probe) + IORING_OP_LAST * sizeof(io_uring_probe_op)>
          bytes{};
  auto* probe = reinterpret_cast<io_uring_probe*>(bytes.data());
  if (ioUringRegister(ring, IORING_REGISTER_PROBE, probe, IORING_OP_LAST) != 0) return false;
  return probe->last_op >= IORING_OP_SEND &&
         (probe->ops[IORING_OP_SEND].flags & IO_URING_OP_SUPPORTED) != 0;
}

}  // namespace

Result<KernelThreadSender> KernelThreadSender::open(int socket, int cpu, const std::string& where,
                                                    unsigned idleMs) {
  const std::string what = "sending thread on CPU " + std::to_string(cpu) + " for " + where;
  if (cpu < 0) return makeError(ErrorCode::kInvalidArgument, what + ": no such CPU");
  io_uring_params params{};
  params.flags = IORING_SETUP_SQPOLL | IORING_SETUP_SQ_AFF;
  params.sq_thread_cpu = static_cast<unsigned>(cpu);
  params.sq_thread_idle = idleMs;
  const int fd = ioUringSetup(kEntries, &params);
  if (fd < 0) {
    const int err = errno;
    if (err == EINVAL) {
      return makeError(ErrorCode::kInvalidArgument,
                       what + ": io_uring_setup: " + errnoText(err) +
                           " (a CPU that is offline or outside this cgroup's cpuset?)");
    }
    return makeError(ErrorCode::kUnsupported,
                     what + ": io_uring_setup: " + errnoText(err) +
                         " (/proc/sys/kernel/io_uring_disabled, a seccomp filter, Linux < 5.11?)");
  }
  KernelThreadSender s;
  s.ring_.reset(fd);
  s.cpu_ = cpu;
  s.where_ = where;
  if (!sendSupported(fd)) {
    return makeError(ErrorCode::kUnsupported, what + ": the kernel's io_uring has no SEND");
  }
  s.sqMapBytes_ = params.sq_off.array + params.sq_entries * sizeof(unsigned);
  s.cqMapBytes_ = params.cq_off.cqes + params.cq_entries * sizeof(io_uring_cqe);
  const bool single = (params.features & IORING_FEAT_SINGLE_MMAP) != 0;
  if (single) s.sqMapBytes_ = s.cqMapBytes_ = std::max(s.sqMapBytes_, s.cqMapBytes_);
  s.sqMap_ = mapRing(fd, s.sqMapBytes_, IORING_OFF_SQ_RING);
  s.cqMap_ = single ? s.sqMap_ : mapRing(fd, s.cqMapBytes_, IORING_OFF_CQ_RING);
  s.sqesBytes_ = params.sq_entries * sizeof(io_uring_sqe);
  s.sqes_ = static_cast<io_uring_sqe*>(mapRing(fd, s.sqesBytes_, IORING_OFF_SQES));
  if (s.sqMap_ == nullptr || s.cqMap_ == nullptr || s.sqes_ == nullptr) {
    return makeError(ErrorCode::kIo, what + ": mapping the io_uring: " + errnoText(errno));
  }
  s.sqTail_ = field<unsigned>(s.sqMap_, params.sq_off.tail);
  s.sqFlags_ = field<unsigned>(s.sqMap_, params.sq_off.flags);
  s.sqArray_ = field<unsigned>(s.sqMap_, params.sq_off.array);
  s.sqMask_ = *field<unsigned>(s.sqMap_, params.sq_off.ring_mask);
  s.cqHead_ = field<unsigned>(s.cqMap_, params.cq_off.head);
  s.cqTail_ = field<unsigned>(s.cqMap_, params.cq_off.tail);
  s.cqMask_ = *field<unsigned>(s.cqMap_, params.cq_off.ring_mask);
  s.cqes_ = field<io_uring_cqe>(s.cqMap_, params.cq_off.cqes);
  // A registered file: the polling thread then needs no reference taken per send (and Linux
  // before 5.11 allows nothing else with SQPOLL).
  if (ioUringRegister(fd, IORING_REGISTER_FILES, &socket, 1) != 0) {
    return makeError(ErrorCode::kIo, what + ": registering the socket: " + errnoText(errno));
  }
  return s;
}

KernelThreadSender::KernelThreadSender(KernelThreadSender&& other) noexcept {
  *this = std::move(other);
}

KernelThreadSender& KernelThreadSender::operator=(KernelThreadSender&& other) noexcept {
  if (this == &other) return *this;
  release();
  ring_ = std::move(other.ring_);
  cpu_ = other.cpu_;
  where_ = std::move(other.where_);
  sqMap_ = std::exchange(other.sqMap_, nullptr);
  sqMapBytes_ = other.sqMapBytes_;
  cqMap_ = std::exchange(other.cqMap_, nullptr);
  cqMapBytes_ = other.cqMapBytes_;
  sqes_ = std::exchange(other.sqes_, nullptr);
  sqesBytes_ = other.sqesBytes_;
  sqTail_ = other.sqTail_;
  sqFlags_ = other.sqFlags_;
  sqArray_ = other.sqArray_;
  sqMask_ = other.sqMask_;
  cqHead_ = other.cqHead_;
  cqTail_ = other.cqTail_;
  cqMask_ = other.cqMask_;
  cqes_ = other.cqes_;
  wakeUps_ = other.wakeUps_;
  return *this;
}

KernelThreadSender::~KernelThreadSender() {
  release();
}

void KernelThreadSender::release() {
  if (sqes_ != nullptr) ::munmap(sqes_, sqesBytes_);
  if (cqMap_ != nullptr && cqMap_ != sqMap_) ::munmap(cqMap_, cqMapBytes_);
  if (sqMap_ != nullptr) ::munmap(sqMap_, sqMapBytes_);
  sqes_ = nullptr;
  cqMap_ = sqMap_ = nullptr;
  ring_.reset();  // the kernel stops the polling thread
}

Result<long> KernelThreadSender::send(ConstBytes frame) {
  if (sqes_ == nullptr) return makeError(ErrorCode::kState, where_ + ": sender moved from");
  // Only this thread writes the tail: a plain read of our own last store.
  const unsigned tail = *sqTail_;
  const unsigned index = tail & sqMask_;
  io_uring_sqe& e = sqes_[index];
  std::memset(&e, 0, sizeof e);
  e.opcode = IORING_OP_SEND;
  e.flags = IOSQE_FIXED_FILE;
  e.fd = kFixedSocket;
  e.addr = reinterpret_cast<std::uint64_t>(frame.data());
  e.len = static_cast<std::uint32_t>(frame.size());
  sqArray_[index] = index;
  // Release: the entry is written before the polling thread can see the new tail.
  __atomic_store_n(sqTail_, tail + 1, __ATOMIC_RELEASE);
  // A full barrier between publishing the tail and reading the thread's flags, so that a
  // thread going to sleep either sees the entry or has set NEED_WAKEUP where we look.
  __atomic_thread_fence(__ATOMIC_SEQ_CST);
  if ((__atomic_load_n(sqFlags_, __ATOMIC_RELAXED) & IORING_SQ_NEED_WAKEUP) != 0) {
    ++wakeUps_;
    if (ioUringEnter(ring_.get(), 0, 0, IORING_ENTER_SQ_WAKEUP) < 0 && errno != EINTR) {
      return makeError(ErrorCode::kIo, where_ + ": waking the sending thread: " + errnoText(errno));
    }
  }
  return awaitCompletion();
}

Result<long> KernelThreadSender::awaitCompletion() {
  const auto spinUntil = std::chrono::steady_clock::now() + kSpinBeforeSleeping;
  for (unsigned looks = 1;; ++looks) {
    const unsigned head = *cqHead_;
    // Acquire: the entry's fields, written before the tail, are seen after it.
    if (head != __atomic_load_n(cqTail_, __ATOMIC_ACQUIRE)) {
      const int res = cqes_[head & cqMask_].res;
      __atomic_store_n(cqHead_, head + 1, __ATOMIC_RELEASE);
      return res;
    }
    if (looks % 64 == 0 && std::chrono::steady_clock::now() >= spinUntil) {
      // Sleep in the kernel until the completion is there (EINTR: look again).
      if (ioUringEnter(ring_.get(), 0, 1, IORING_ENTER_GETEVENTS) < 0 && errno != EINTR) {
        return makeError(ErrorCode::kIo, where_ + ": waiting for a send: " + errnoText(errno));
      }
      continue;
    }
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
}

}  // namespace ecsim
