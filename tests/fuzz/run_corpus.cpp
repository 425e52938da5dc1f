// Runs a libFuzzer harness over input files without libFuzzer and without instrumentation, so
// that per-input timings (HQP_FUZZ_STATS) are those of an ordinary optimized build
// (docs/realtime.md, "Worst case"). Link it with one fuzz_*.cpp:
//   clang++-14 -std=c++17 -O3 -I include -I tests -I tests/fuzz -I /usr/include/eigen3 \
//     -I /usr/lib/llvm-14/lib/clang/14.0.6/include tests/fuzz/fuzz_hqp.cpp tests/fuzz/run_corpus.cpp
//   ./a.out corpus_dir/*
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::ifstream f(argv[i], std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("%d inputs\n", argc - 1);
  return 0;
}
