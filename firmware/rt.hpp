#pragma once
// A periodic real-time loop as it runs on a robot PC: mlockall, a prefaulted stack,
// SCHED_FIFO, CPU affinity, a CPU-idle latency request, absolute clock_nanosleep on
// CLOCK_MONOTONIC, an overrun counter, and per-tick wake-up latency and compute time in a ring
// buffer preallocated before start.
// Where the process lacks the privileges (no CAP_SYS_NICE / RLIMIT_RTPRIO, RLIMIT_MEMLOCK),
// start() says which step failed and the loop runs anyway; the figures are then not RT.

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace hqp::firmware {

struct RtOptions {
  int priority = 80;              // SCHED_FIFO priority (1..99); 0: stay SCHED_OTHER
  int cpu = -1;                   // pin to this CPU; −1: no affinity
  bool lock_memory = true;        // mlockall(MCL_CURRENT | MCL_FUTURE)
  std::size_t stack_prefault = 256 * 1024;  // bytes of stack touched before start
  // A PM QoS request on /dev/cpu_dma_latency, held while the process lives (cyclictest makes the
  // same one): no CPU enters an idle state that takes longer than this to leave. The loop's CPU
  // idles between ticks; without the request its wake-up and tick were slower on an idle
  // machine (docs/realtime.md, "Measured jitter"). -1: no request.
  int cpu_dma_latency_us = 0;
};

struct RtState {
  bool memory_locked = false;
  bool fifo = false;
  bool pinned = false;
  int latency_fd = -1;  // open while the cpu_dma_latency request holds
  bool realTime() const { return memory_locked && fifo; }
};

// Ends the cpu_dma_latency request (closing its file ends it; so does the process's exit).
inline void releaseCpuLatency(RtState& st) {
  if (st.latency_fd >= 0) close(st.latency_fd);
  st.latency_fd = -1;
}

// Touches `bytes` of stack so that the tick never page-faults on it (with mlockall, the
// pages stay resident).
__attribute__((noinline)) inline void prefaultStack(std::size_t bytes) {
  constexpr std::size_t kChunk = 4096;
  unsigned char page[kChunk];
  std::memset(page, 0, kChunk);
  asm volatile("" : : "r"(page) : "memory");  // keep the writes
  if (bytes > kChunk) prefaultStack(bytes - kChunk);
}

// Start-up steps in order; each failure is reported on stderr and skipped.
inline RtState startRealTime(const RtOptions& o) {
  RtState st;
  if (o.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) st.memory_locked = true;
    else std::fprintf(stderr, "rt: mlockall failed (%s): pages may fault in the loop -> NOT real time\n",
                      std::strerror(errno));
  }
  prefaultStack(o.stack_prefault);
  if (o.cpu_dma_latency_us >= 0) {
    const int fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    const std::int32_t us = o.cpu_dma_latency_us;
    if (fd >= 0 && write(fd, &us, sizeof us) == static_cast<ssize_t>(sizeof us)) {
      st.latency_fd = fd;
    } else {
      std::fprintf(stderr, "rt: no cpu_dma_latency request of %d us (%s): idle CPUs may wake slowly\n", us,
                   std::strerror(errno));
      if (fd >= 0) close(fd);
    }
  }
  if (o.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(o.cpu, &set);
    const int e = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
    if (e == 0) st.pinned = true;
    else std::fprintf(stderr, "rt: cannot pin to CPU %d (%s)\n", o.cpu, std::strerror(e));
  }
  if (o.priority > 0) {
    sched_param sp{};
    sp.sched_priority = o.priority;
    const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    if (e == 0) st.fifo = true;
    else std::fprintf(stderr, "rt: SCHED_FIFO priority %d not permitted (%s): running as SCHED_OTHER -> NOT real time\n",
                      o.priority, std::strerror(e));
  }
  return st;
}

struct TickSample {
  float wake_us = 0.0f;     // wake-up latency: actual wake time − deadline
  float compute_us = 0.0f;  // the controller's tick
  float io_us = 0.0f;       // backend: waiting for and exchanging the process image
};

inline std::int64_t toNs(const timespec& t) { return std::int64_t{t.tv_sec} * 1000000000 + t.tv_nsec; }
inline timespec fromNs(std::int64_t ns) {
  timespec t;
  t.tv_sec = static_cast<time_t>(ns / 1000000000);
  t.tv_nsec = static_cast<long>(ns % 1000000000);
  return t;
}
inline std::int64_t nowNs() {
  timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return toNs(t);
}

// Set by SIGINT / SIGTERM; the loop ends at the next tick.
inline std::atomic<bool> g_stop_requested{false};
inline void requestStop(int) { g_stop_requested.store(true, std::memory_order_relaxed); }
inline void installStopHandler() {
  struct sigaction sa {};
  sa.sa_handler = requestStop;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

// The periodic loop. `tick(k, sample)` does one cycle, or returns false to stop without one. Samples go
// to a ring buffer of `capacity` entries allocated here, before the first tick (the last
// `capacity` ticks are kept).
class PeriodicLoop {
 public:
  PeriodicLoop(std::int64_t period_ns, std::size_t capacity) : period_ns_(period_ns), ring_(capacity) {}

  template <class Tick>
  void run(long max_ticks, Tick&& tick) {
    std::int64_t next = nowNs() + period_ns_;
    for (long k = 0; k < max_ticks && !g_stop_requested.load(std::memory_order_relaxed); ++k) {
      const timespec ts = fromNs(next);
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR &&
             !g_stop_requested.load(std::memory_order_relaxed)) {
      }
      TickSample& s = ring_[static_cast<std::size_t>(k) % ring_.size()];
      s.wake_us = static_cast<float>(static_cast<double>(nowNs() - next) * 1e-3);
      if (!tick(k, s)) break;  // the backend ended (log done, plant gone): not a tick
      ++ticks_;
      next += period_ns_;
      const std::int64_t end = nowNs();
      if (end > next) {  // missed the next deadline: count it, resume on the period grid
        ++overruns_;
        next += ((end - next) / period_ns_ + 1) * period_ns_;
      }
    }
  }

  long ticks() const { return ticks_; }
  long overruns() const { return overruns_; }
  // The recorded samples in tick order (after the run).
  std::vector<TickSample> samples() const {
    std::vector<TickSample> out;
    const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(ticks_), ring_.size());
    const std::size_t first = static_cast<std::size_t>(ticks_) - n;
    for (std::size_t i = 0; i < n; ++i) out.push_back(ring_[(first + i) % ring_.size()]);
    return out;
  }

 private:
  std::int64_t period_ns_;
  std::vector<TickSample> ring_;
  long ticks_ = 0, overruns_ = 0;
};

struct Distribution {
  double min = 0, mean = 0, p50 = 0, p99 = 0, p999 = 0, max = 0;
};

inline Distribution distribution(std::vector<double> v) {
  Distribution d;
  if (v.empty()) return d;
  std::sort(v.begin(), v.end());
  auto q = [&](double p) {
    const std::size_t i = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size()))) - 1;
    return v[std::min(i, v.size() - 1)];
  };
  d.min = v.front();
  d.max = v.back();
  double s = 0.0;
  for (double x : v) s += x;
  d.mean = s / static_cast<double>(v.size());
  d.p50 = q(0.5);
  d.p99 = q(0.99);
  d.p999 = q(0.999);
  return d;
}

}  // namespace hqp::firmware
