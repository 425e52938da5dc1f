#pragma once
// The process image the controller and the plant share through POSIX shared memory, as an
// EtherCAT master's: one sensor frame in and one command frame out per tick. No locks: each
// frame is a seqlock (odd sequence = being written; a reader that sees the sequence change
// retries) and carries a checksum of its payload, so a torn frame could not pass unnoticed.
// Lockstep: the plant publishes sensor frame k, the controller answers with command frame k,
// the plant applies it, steps 1 ms and publishes sensor frame k + 1. A side that has to wait
// sleeps on a doorbell (a futex the writer rings after each frame) instead of polling: polling
// with short sleeps costs a whole CPU and gets a SCHED_FIFO process throttled by the kernel.

#include <linux/futex.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <climits>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "walker3_firmware.hpp"

namespace hqp::firmware {

// FNV-1a over the payload's bytes.
inline std::uint64_t checksum(const void* p, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(p);
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  return h;
}

template <class T>
struct SeqFrame {
  // Frames are copied as bytes: T holds fixed-size Eigen objects only (plain arrays of
  // doubles) and the two processes are built from the same headers. Lock-free atomics only
  // work across processes.
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free);
  std::atomic<std::uint64_t> seq{0};  // odd while written
  std::uint64_t frame = ~std::uint64_t{0};  // tick index of the payload; none before the first write
  std::uint64_t sum = 0;               // checksum(data)
  T data;

  // Single writer.
  void write(const T& v, std::uint64_t frame_no) {
    const std::uint64_t s = seq.load(std::memory_order_relaxed);
    seq.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    std::memcpy(static_cast<void*>(&data), &v, sizeof(T));
    frame = frame_no;
    sum = checksum(&v, sizeof(T));
    seq.store(s + 2, std::memory_order_release);
  }
  // False if the writer was active (retry). On true, `torn` tells whether the payload failed
  // its checksum despite a stable sequence (never expected: the handshake's own check).
  bool read(T& out, std::uint64_t& frame_no, bool& torn) const {
    const std::uint64_t s1 = seq.load(std::memory_order_acquire);
    if (s1 & 1u) return false;
    std::memcpy(static_cast<void*>(&out), &data, sizeof(T));
    frame_no = frame;
    const std::uint64_t sm = sum;
    std::atomic_thread_fence(std::memory_order_acquire);
    if (seq.load(std::memory_order_relaxed) != s1) return false;
    torn = checksum(&out, sizeof(T)) != sm;
    return true;
  }
};

// A counter the writer increments after each frame and wakes the other process on.
struct Doorbell {
  std::atomic<std::uint32_t> count{0};
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t), "a futex word");

  std::uint32_t value() const { return count.load(std::memory_order_acquire); }
  void ring() {
    count.fetch_add(1, std::memory_order_release);
    syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&count), FUTEX_WAKE, INT_MAX, nullptr, nullptr, 0);
  }
  // Sleeps while the count is still `seen` (read before checking the frame), at most timeout_ns.
  void wait(std::uint32_t seen, long timeout_ns) {
    timespec t{timeout_ns / 1000000000, timeout_ns % 1000000000};
    syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&count), FUTEX_WAIT, seen, &t, nullptr, 0);
  }
};

struct ProcessImage {
  static constexpr std::uint64_t kMagic = 0x4851505f52544931ull;  // "HQP_RTI1"
  std::atomic<std::uint64_t> magic{0};  // set by the plant once frame 0 is published
  std::atomic<int> stop{0};             // controller -> plant: finish after this frame
  std::atomic<std::uint64_t> plant_torn{0};     // command frames that failed their checksum
  std::atomic<std::uint64_t> plant_retries{0};  // command reads that met a write in progress
  SeqFrame<Sensors> sensors;
  SeqFrame<Command> command;
  Doorbell sensors_bell, command_bell;
};

}  // namespace hqp::firmware
