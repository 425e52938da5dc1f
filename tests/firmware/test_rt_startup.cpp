// The loop's start-up (firmware/rt.hpp): its cpu_dma_latency request, read back from the
// kernel's own device (the PM QoS target every CPU's idle governor obeys).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>

#include "rt.hpp"

namespace {

namespace fw = hqp::firmware;
constexpr const char* kDevice = "/dev/cpu_dma_latency";

// The current system-wide target in µs (the smallest request held), or -1 if unreadable.
std::int64_t currentTarget() {
  std::FILE* f = std::fopen(kDevice, "rb");
  if (f == nullptr) return -1;
  std::int32_t v = 0;
  const bool ok = std::fread(&v, sizeof v, 1, f) == 1;
  std::fclose(f);
  return ok ? v : -1;
}

fw::RtOptions quietOptions() {  // no scheduling or memory changes for the test process
  fw::RtOptions o;
  o.priority = 0;
  o.lock_memory = false;
  o.stack_prefault = 0;
  return o;
}

TEST(RtStartup, HoldsTheCpuDmaLatencyRequestUntilReleased) {
  if (access(kDevice, W_OK) != 0) GTEST_SKIP() << kDevice << " not writable (needs root)";
  const std::int64_t before = currentTarget();
  if (before == 0) GTEST_SKIP() << "another process holds a request of 0 us (cyclictest, a running loop)";
  ASSERT_GT(before, 0) << "cannot read " << kDevice;
  fw::RtOptions o = quietOptions();
  o.cpu_dma_latency_us = 0;
  fw::RtState st = fw::startRealTime(o);
  ASSERT_GE(st.latency_fd, 0);
  EXPECT_EQ(currentTarget(), 0);
  fw::releaseCpuLatency(st);
  EXPECT_EQ(st.latency_fd, -1);
  EXPECT_EQ(currentTarget(), before);
}

TEST(RtStartup, MakesNoRequestWhenAskedNotTo) {
  const std::int64_t before = currentTarget();
  fw::RtOptions o = quietOptions();
  o.cpu_dma_latency_us = -1;
  const fw::RtState st = fw::startRealTime(o);
  EXPECT_EQ(st.latency_fd, -1);
  EXPECT_EQ(currentTarget(), before);
}

}  // namespace
