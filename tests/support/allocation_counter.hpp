#pragma once
// A counting replacement of the global operator new/delete for no-allocation tests. It defines
// the global allocation functions, so include it in exactly one translation unit per test binary
// (our test binaries are one file each). Counting is on unless a test switches it off around
// set-up code; tests compare g_news before and after the code under test and also check that
// an allocation made while counting is seen (so the hook cannot silently be bypassed).
// With HQP_COUNT_MALLOC defined and the binary linked with -Wl,--wrap=malloc,--wrap=calloc,
// --wrap=realloc, malloc calls from the binary's own objects (Eigen's aligned_malloc included)
// are counted in g_mallocs as well.

#include <atomic>
#include <cstdlib>
#include <new>

namespace hqp::testing {
inline std::atomic<long> g_news{0};         // operator new calls while counting
inline std::atomic<bool> g_counting{true};  // count or not
inline std::atomic<long> g_mallocs{0};      // malloc/calloc/realloc calls while counting (HQP_COUNT_MALLOC)
}  // namespace hqp::testing

#ifdef HQP_COUNT_MALLOC
extern "C" {
void* __real_malloc(std::size_t);
void* __real_calloc(std::size_t, std::size_t);
void* __real_realloc(void*, std::size_t);
inline void hqpCountMalloc() {
  if (hqp::testing::g_counting.load(std::memory_order_relaxed))
    hqp::testing::g_mallocs.fetch_add(1, std::memory_order_relaxed);
}
void* __wrap_malloc(std::size_t n) {
  hqpCountMalloc();
  return __real_malloc(n);
}
void* __wrap_calloc(std::size_t n, std::size_t s) {
  hqpCountMalloc();
  return __real_calloc(n, s);
}
void* __wrap_realloc(void* p, std::size_t n) {
  hqpCountMalloc();
  return __real_realloc(p, n);
}
}
#endif

inline void* hqpCountedNew(std::size_t n) {
  if (hqp::testing::g_counting.load(std::memory_order_relaxed))
    hqp::testing::g_news.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}

inline void* hqpCountedAlignedNew(std::size_t n, std::align_val_t al) {
  if (hqp::testing::g_counting.load(std::memory_order_relaxed))
    hqp::testing::g_news.fetch_add(1, std::memory_order_relaxed);
  const std::size_t a = static_cast<std::size_t>(al);
  if (void* p = std::aligned_alloc(a, ((n + a - 1) / a) * a)) return p;
  throw std::bad_alloc();
}

void* operator new(std::size_t n) { return hqpCountedNew(n); }
void* operator new[](std::size_t n) { return hqpCountedNew(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void* operator new(std::size_t n, std::align_val_t a) { return hqpCountedAlignedNew(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return hqpCountedAlignedNew(n, a); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
