// hqp_rt_loop: the Walker3 balance controller in a 1 kHz firmware-style loop (docs/realtime.md).
// Backends: the MuJoCo plant in another process (hqp_rt_plant) through a shared-memory process
// image, or the replay of a sensor log. After the run: the tick samples as CSV, a summary, and
// with --verify (replay) a bit-for-bit comparison with the same controller run offline.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "process_image.hpp"
#include "rt.hpp"
#include "sensor_log.hpp"
#include "support/allocation_counter.hpp"  // counting new and malloc: no allocation after start
#include "walker3_firmware.hpp"

namespace fw = hqp::firmware;

namespace {

// Sleeps `ns` (relative): while waiting for the plant process to appear.
void pause(long ns) {
  timespec t{0, ns};
  clock_nanosleep(CLOCK_MONOTONIC, 0, &t, nullptr);
}

// Controller side of the process image (hqp_rt_plant is the other side).
class ShmBackend {
 public:
  std::string open(const std::string& name, double timeout_s) {
    const std::int64_t until = fw::nowNs() + static_cast<std::int64_t>(timeout_s * 1e9);
    int fd = -1;
    while ((fd = shm_open(name.c_str(), O_RDWR, 0)) < 0) {
      if (fw::nowNs() > until || fw::g_stop_requested.load())
        return "no process image '" + name + "' (is hqp_rt_plant running?)";
      pause(10'000'000);
    }
    void* p = mmap(nullptr, sizeof(fw::ProcessImage), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    ::close(fd);
    if (p == MAP_FAILED) return "cannot map '" + name + "'";
    img_ = static_cast<fw::ProcessImage*>(p);
    while (img_->magic.load(std::memory_order_acquire) != fw::ProcessImage::kMagic) {
      if (fw::nowNs() > until || fw::g_stop_requested.load())
        return "process image '" + name + "' never became ready";
      pause(1'000'000);
    }
    return {};
  }
  ~ShmBackend() {
    if (img_) munmap(img_, sizeof(fw::ProcessImage));
  }
  // Sensor frame k; waits for the plant (lockstep) up to 1 s.
  bool read(long k, fw::Sensors& s) {
    const std::int64_t until = fw::nowNs() + 1'000'000'000;
    for (bool first = true;; first = false) {
      const std::uint32_t seen = img_->sensors_bell.value();
      std::uint64_t frame = 0;
      bool torn = false;
      if (img_->sensors.read(s, frame, torn)) {
        if (static_cast<long>(frame) == k) {
          torn_ += torn;
          return true;
        }
      } else {
        ++retries_;
      }
      if (first) ++late_;
      if (fw::nowNs() > until || fw::g_stop_requested.load(std::memory_order_relaxed)) return false;
      img_->sensors_bell.wait(seen, 10'000'000);
    }
  }
  void write(long k, const fw::Command& c) {
    img_->command.write(c, static_cast<std::uint64_t>(k));
    img_->command_bell.ring();
  }
  void finish() {
    if (!img_) return;
    img_->stop.store(1, std::memory_order_release);
    img_->command_bell.ring();
  }
  long late() const { return late_; }
  long retries() const { return retries_; }
  long torn() const { return torn_; }
  long plantTorn() const { return img_ ? static_cast<long>(img_->plant_torn.load()) : 0; }
  long plantRetries() const { return img_ ? static_cast<long>(img_->plant_retries.load()) : 0; }

 private:
  fw::ProcessImage* img_ = nullptr;
  long late_ = 0, retries_ = 0, torn_ = 0;
};

void printDistribution(std::FILE* f, const char* what, const fw::Distribution& d) {
  std::fprintf(f, "%-22s min %8.1f  mean %8.1f  p50 %8.1f  p99 %8.1f  p99.9 %8.1f  max %8.1f\n", what, d.min,
               d.mean, d.p50, d.p99, d.p999, d.max);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Walker3 balance controller in a 1 kHz real-time loop"};
  std::string backend = "shm", shm_name = "/hqp_walker3", log_path, config_path = HQP_FIRMWARE_CONFIG, out_dir;
  long ticks = 0;
  int ring = 600000;
  fw::RtOptions rt;
  bool no_mlock = false, verify = false, check = false;
  double budget_us = -1.0;
  int budget_iterations = -1;
  app.add_option("--backend", backend, "shm: MuJoCo plant process (hqp_rt_plant); replay: a sensor log")
      ->check(CLI::IsMember({"shm", "replay"}));
  app.add_option("--shm", shm_name, "shared-memory process image name (shm backend)");
  app.add_option("--log", log_path, "sensor log CSV (replay backend; hqp_rt_plant --record writes one)");
  app.add_option("--config", config_path, "controller YAML")->check(CLI::ExistingFile);
  app.add_option("--ticks", ticks, "ticks to run (0: until SIGINT, or the log's end)")->check(CLI::NonNegativeNumber);
  app.add_option("--priority", rt.priority, "SCHED_FIFO priority (0: SCHED_OTHER)")->check(CLI::Range(0, 99));
  app.add_option("--cpu", rt.cpu, "pin the loop to this CPU (-1: no affinity)")->check(CLI::Range(-1, 1023));
  app.add_flag("--no-mlock", no_mlock, "skip mlockall");
  app.add_option("--cpu-dma-latency", rt.cpu_dma_latency_us,
                 "hold a /dev/cpu_dma_latency request of this many us while running (-1: none)")
      ->check(CLI::Range(-1, 2000000000));
  app.add_option("--ring", ring, "tick samples kept (ring buffer, allocated before start)")->check(CLI::PositiveNumber);
  app.add_option("--out", out_dir, "write rt_ticks.csv and rt_summary.txt here");
  app.add_option("--budget-us", budget_us, "override qp.hqp.budget_us (0: none)")->check(CLI::NonNegativeNumber);
  app.add_option("--budget-iterations", budget_iterations, "override qp.hqp.budget_iterations (0: none)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--verify", verify, "replay: compare every command with the controller run offline on the same sensors "
                                   "(and with the log's currents, if it has them)");
  app.add_flag("--check", check, "exit 1 on an allocation after start, a torn frame, a safe-mode tick, a missing "
                                 "tick or a --verify difference");
  CLI11_PARSE(app, argc, argv);
  rt.lock_memory = !no_mlock;
  fw::installStopHandler();  // SIGINT also ends the wait for the plant

  // ---- Set-up (allocation allowed) ----
  fw::Config config;
  try {
    config = fw::loadConfig(config_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  if (budget_us >= 0.0) config.qp.hqp.budget_us = budget_us;
  if (budget_iterations >= 0) config.qp.hqp.budget_iterations = budget_iterations;
  auto controller = std::make_unique<fw::FirmwareController>(config);

  ShmBackend shm;
  std::vector<fw::LogRow> rows;
  bool log_has_current = false;
  if (backend == "shm") {
    const std::string e = shm.open(shm_name, 10.0);
    if (!e.empty()) {
      std::fprintf(stderr, "%s\n", e.c_str());
      return 2;
    }
  } else {
    if (log_path.empty()) {
      std::fprintf(stderr, "--backend replay needs --log\n");
      return 2;
    }
    const std::string e = fw::readSensorLog(log_path, rows, log_has_current);
    if (!e.empty()) {
      std::fprintf(stderr, "%s\n", e.c_str());
      return 2;
    }
    if (ticks == 0 || ticks > static_cast<long>(rows.size())) ticks = static_cast<long>(rows.size());
  }
  const long max_ticks = ticks > 0 ? ticks : (1L << 62);
  std::vector<fw::Command> sent(backend == "replay" ? rows.size() : 0);
  fw::PeriodicLoop loop(1'000'000, static_cast<std::size_t>(ring));
  long safe_ticks = 0, cut_ticks = 0;
  int max_iterations = 0, first_safe_reason = 0;
  fw::Sensors s;
  fw::Command cmd;

  const fw::RtState rts = fw::startRealTime(rt);
  const bool is_rt = rts.realTime();
  if (!is_rt)
    std::fprintf(stderr, "rt: running WITHOUT real-time guarantees; the figures below are marked NOT RT\n");

  {  // the counters see allocations at all (the hook cannot be silently bypassed)
    const long m0 = hqp::testing::g_mallocs.load(), n0 = hqp::testing::g_news.load();
    void* p = std::malloc(64);
    auto* q = new int(1);
    asm volatile("" : : "r"(p), "r"(q) : "memory");
    std::free(p);
    delete q;
    if (hqp::testing::g_mallocs.load() == m0 || hqp::testing::g_news.load() == n0) {
      std::fprintf(stderr, "rt_loop: allocation counters are not hooked\n");
      return 2;
    }
  }

  const bool use_shm = backend == "shm";  // decided once, not per tick

  // ---- The loop: no allocation from here on (operator new and malloc are counted) ----
  const long news_before = hqp::testing::g_news.load() + hqp::testing::g_mallocs.load();
  loop.run(max_ticks, [&](long k, fw::TickSample& sample) {
    const std::int64_t t0 = fw::nowNs();
    bool ok = true;
    if (use_shm) ok = shm.read(k, s);
    else s = rows[static_cast<std::size_t>(k)].sensors;
    if (!ok) return false;
    const std::int64_t t1 = fw::nowNs();
    controller->tick(s, cmd);
    const std::int64_t t2 = fw::nowNs();
    const fw::TickInfo info = controller->info();
    if (info.safe_mode && safe_ticks++ == 0) first_safe_reason = info.safe_reason;
    cut_ticks += info.cut_level >= 0;
    max_iterations = std::max(max_iterations, info.iterations);
    if (use_shm) shm.write(k, cmd);
    else sent[static_cast<std::size_t>(k)] = cmd;
    sample.compute_us = static_cast<float>(static_cast<double>(t2 - t1) * 1e-3);
    sample.io_us = static_cast<float>(static_cast<double>(t1 - t0 + fw::nowNs() - t2) * 1e-3);
    return true;
  });
  const long allocations = hqp::testing::g_news.load() + hqp::testing::g_mallocs.load() - news_before;
  if (backend == "shm") shm.finish();

  // ---- After the run ----
  const std::vector<fw::TickSample> samples = loop.samples();
  std::vector<double> wake, compute, io;
  for (const auto& x : samples) {
    wake.push_back(x.wake_us);
    compute.push_back(x.compute_us);
    io.push_back(x.io_us);
  }
  std::string summary;
  {
    char buf[512];
    auto add = [&](const char* fmt, auto... a) {
      std::snprintf(buf, sizeof buf, fmt, a...);
      summary += buf;
    };
    add("rt_loop: backend %s, %s: SCHED_FIFO %s (priority %d), mlockall %s, CPU %s, cpu_dma_latency %s\n",
        backend.c_str(), is_rt ? "REAL TIME" : "NOT RT", rts.fifo ? "yes" : "no", rt.priority,
        rts.memory_locked ? "yes" : "no", rts.pinned ? std::to_string(rt.cpu).c_str() : "any",
        rts.latency_fd >= 0 ? (std::to_string(rt.cpu_dma_latency_us) + " us").c_str() : "none");
    add("ticks: %ld  overruns: %ld  safe-mode ticks: %ld (first reason %d)  budget-cut ticks: %ld  "
        "max QP iterations per tick: %d  allocations after start: %ld\n",
        loop.ticks(), loop.overruns(), safe_ticks, first_safe_reason, cut_ticks, max_iterations, allocations);
    if (backend == "shm")
      add("process image: late sensor frames %ld, seqlock retries %ld (controller) %ld (plant), torn frames %ld "
          "(controller) %ld (plant)\n",
          shm.late(), shm.retries(), shm.plantRetries(), shm.torn(), shm.plantTorn());
  }
  std::fputs(summary.c_str(), stdout);
  printDistribution(stdout, "wake-up latency (us)", fw::distribution(wake));
  printDistribution(stdout, "compute (us)", fw::distribution(compute));
  printDistribution(stdout, "io (us)", fw::distribution(io));

  long differ_offline = 0, differ_log = 0;
  if (verify && backend == "replay") {
    fw::FirmwareController offline(config);
    fw::Command c;
    for (long k = 0; k < loop.ticks(); ++k) {
      offline.tick(rows[static_cast<std::size_t>(k)].sensors, c);
      const auto& r = sent[static_cast<std::size_t>(k)];
      differ_offline += !(c.current == r.current && c.torque == r.torque && c.safe_mode == r.safe_mode);
      if (log_has_current) differ_log += !(rows[static_cast<std::size_t>(k)].command.current == r.current);
    }
    std::printf("verify: %ld of %ld commands differ from the offline controller's", differ_offline, loop.ticks());
    if (log_has_current) std::printf("; %ld differ from the currents in the log", differ_log);
    std::printf("\n");
  }

  if (!out_dir.empty()) {
    std::filesystem::create_directories(out_dir);
    if (std::FILE* f = std::fopen((out_dir + "/rt_ticks.csv").c_str(), "w")) {
      for (std::size_t a = 0, b; a < summary.size(); a = b + 1) {  // the summary as # lines
        b = summary.find('\n', a);
        if (b == std::string::npos) b = summary.size();
        std::fprintf(f, "# %s\n", summary.substr(a, b - a).c_str());
      }
      std::fprintf(f, "tick,wake_us,compute_us,io_us\n");
      const long first = loop.ticks() - static_cast<long>(samples.size());
      for (std::size_t i = 0; i < samples.size(); ++i)
        std::fprintf(f, "%ld,%.3f,%.3f,%.3f\n", first + static_cast<long>(i), samples[i].wake_us,
                     samples[i].compute_us, samples[i].io_us);
      std::fclose(f);
    }
    if (std::FILE* f = std::fopen((out_dir + "/rt_summary.txt").c_str(), "w")) {
      std::fputs(summary.c_str(), f);
      printDistribution(f, "wake-up latency (us)", fw::distribution(wake));
      printDistribution(f, "compute (us)", fw::distribution(compute));
      printDistribution(f, "io (us)", fw::distribution(io));
      std::fclose(f);
    }
  }

  if (check) {
    const bool missing = ticks > 0 && loop.ticks() < ticks && !fw::g_stop_requested.load();
    if (allocations > 0 || shm.torn() > 0 || shm.plantTorn() > 0 || safe_ticks > 0 || missing ||
        differ_offline > 0 || differ_log > 0) {
      std::printf("check: FAILED\n");
      return 1;
    }
    std::printf("check: passed\n");
  }
  return 0;
}
