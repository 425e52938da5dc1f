// hqp_rt_plant: the MuJoCo Walker3 (Simulation) as the hardware behind a shared-memory process
// image (firmware/process_image.hpp), in lockstep with hqp_rt_loop: publish sensor frame k,
// wait for command frame k, apply it, step 1 ms, publish frame k + 1. Optionally writes the
// sensor log the replay backend reads, with the current the controller answered each frame with.
#include <fcntl.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include "process_image.hpp"
#include "rt.hpp"
#include "sensor_log.hpp"
#include "simulation.hpp"

namespace fw = hqp::firmware;

int main(int argc, char** argv) {
  CLI::App app{"MuJoCo Walker3 plant for hqp_rt_loop (shared-memory process image)"};
  std::string shm_name = "/hqp_walker3", record;
  fw::RtOptions rt;
  rt.priority = 0;
  double timeout_s = 10.0;
  app.add_option("--shm", shm_name, "process image name");
  app.add_option("--record", record, "write the sensor log (with the commanded currents) here");
  app.add_option("--cpu", rt.cpu, "pin the plant to this CPU (-1: no affinity)")->check(CLI::Range(-1, 1023));
  app.add_option("--priority", rt.priority, "SCHED_FIFO priority, as hardware would answer (0: SCHED_OTHER)")
      ->check(CLI::Range(0, 99));
  app.add_option("--timeout", timeout_s, "give up when no command comes for this long (s)")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  hqp::sim::SimulationOptions so;
  so.scene = HQP_SIM_SCENE;
  so.plant = HQP_SIM_PLANT;
  hqp::sim::Simulation sim(so);
  sim.reset();
  fw::installStopHandler();  // SIGINT: finish, write the log, remove the image
  rt.lock_memory = rt.priority > 0;
  rt.cpu_dma_latency_us = rt.priority > 0 ? 0 : -1;
  fw::startRealTime(rt);  // the same start-up as the loop; failures are reported, not fatal

  shm_unlink(shm_name.c_str());  // a stale image of an earlier run
  const int fd = shm_open(shm_name.c_str(), O_CREAT | O_EXCL | O_RDWR, 0600);
  if (fd < 0 || ftruncate(fd, sizeof(fw::ProcessImage)) != 0) {
    std::perror("rt_plant: shm_open");
    return 2;
  }
  void* mem = mmap(nullptr, sizeof(fw::ProcessImage), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  close(fd);
  if (mem == MAP_FAILED) {
    std::perror("rt_plant: mmap");
    return 2;
  }
  auto* img = new (mem) fw::ProcessImage;

  std::vector<fw::LogRow> log;
  fw::Sensors s;
  fw::Command cmd;
  sim.readSensors(s);
  img->sensors.write(s, 0);
  img->magic.store(fw::ProcessImage::kMagic, std::memory_order_release);
  std::printf("rt_plant: process image %s ready\n", shm_name.c_str());
  std::fflush(stdout);

  long k = 0;
  int rc = 0;
  for (;; ++k) {
    // Wait for command frame k (the controller's answer to sensor frame k).
    timespec last;
    clock_gettime(CLOCK_MONOTONIC, &last);
    bool got = false;
    while (!got) {
      const std::uint32_t seen = img->command_bell.value();
      std::uint64_t frame = 0;
      bool torn = false;
      if (img->command.read(cmd, frame, torn)) {
        if (static_cast<long>(frame) == k) {
          got = true;
          if (torn) img->plant_torn.fetch_add(1);
          break;
        }
      } else {
        img->plant_retries.fetch_add(1);
      }
      if (img->stop.load(std::memory_order_acquire) || fw::g_stop_requested.load()) break;
      timespec now;
      clock_gettime(CLOCK_MONOTONIC, &now);
      if (static_cast<double>(now.tv_sec - last.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec - last.tv_nsec) >
          timeout_s) {
        std::fprintf(stderr, "rt_plant: no command for frame %ld within %.1f s\n", k, timeout_s);
        rc = 1;
        break;
      }
      img->command_bell.wait(seen, 10'000'000);
    }
    if (!got) break;
    if (!record.empty()) log.push_back({s, cmd});
    sim.applyCommand(cmd);
    sim.step();
    sim.readSensors(s);
    img->sensors.write(s, static_cast<std::uint64_t>(k + 1));
    img->sensors_bell.ring();
  }
  std::printf("rt_plant: %ld frames, torso height %.3f m, pitch %.4f rad, torn command frames %lu\n", k,
              sim.torsoHeight(), sim.torsoPitch(), static_cast<unsigned long>(img->plant_torn.load()));
  if (!record.empty()) {
    if (std::FILE* f = std::fopen(record.c_str(), "w")) {
      fw::writeSensorLogHeader(f, true);
      for (const auto& r : log) fw::writeSensorLogRow(f, r.sensors, &r.command);
      std::fclose(f);
      std::printf("rt_plant: sensor log %s (%zu rows)\n", record.c_str(), log.size());
    } else {
      std::fprintf(stderr, "rt_plant: cannot write %s\n", record.c_str());
      rc = 2;
    }
  }
  munmap(mem, sizeof(fw::ProcessImage));
  shm_unlink(shm_name.c_str());
  return rc;
}
