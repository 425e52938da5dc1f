// hqp_sim: Walker3 in MuJoCo 2.2 with the 1 kHz sensor -> current loop (docs/simulation.md).
//   hqp_sim --scenario stand --duration 10 --out DIR [--video] [--driver controller|pd] [--noise]
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "run.hpp"
#include "simulation.hpp"

#ifndef HQP_SIM_SCENE
#define HQP_SIM_SCENE ""
#endif
#ifndef HQP_SIM_PLANT
#define HQP_SIM_PLANT ""
#endif
#ifndef HQP_SIM_CONTROLLER_CONFIG
#define HQP_SIM_CONTROLLER_CONFIG ""
#endif

int main(int argc, char** argv) {
  CLI::App app{"Walker3 balance simulation (MuJoCo 2.2, 1 kHz sensor -> current loop)"};
  hqp::sim::SimulationOptions sim_opt;
  sim_opt.scene = HQP_SIM_SCENE;
  sim_opt.plant = HQP_SIM_PLANT;
  hqp::sim::RunOptions run;
  run.progress = true;
  std::string driver_name = hqp::sim::balanceControllerAvailable() ? "controller" : "pd";
  std::string controller_config = HQP_SIM_CONTROLLER_CONFIG;
  std::string solver = "hqp";
  app.add_option("--scenario", run.scenario, "scenario")->check(CLI::IsMember({"stand"}))->capture_default_str();
  app.add_option("--duration", run.duration, "simulated time (s)")->check(CLI::Range(0.001, 3600.0))->capture_default_str();
  app.add_option("--out", run.out_dir, "output directory (CSV log, video)");
  app.add_flag("--video", run.video, "render an MP4 headless (EGL + ffmpeg; slow)");
  app.add_option("--driver", driver_name, "controller (balance controller) or pd (joint PD stand-in)")
      ->check(CLI::IsMember({"controller", "pd"}))->capture_default_str();
  app.add_option("--controller", solver, "balance controller solver")->check(CLI::IsMember({"hqp", "wqp"}))
      ->capture_default_str();
  app.add_option("--controller-config", controller_config, "controller YAML")->capture_default_str();
  app.add_option("--scene", sim_opt.scene, "scene MJCF")->capture_default_str();
  app.add_option("--plant", sim_opt.plant, "plant parameter YAML")->capture_default_str();
  app.add_option("--substeps", sim_opt.substeps, "physics steps per 1 ms tick")->check(CLI::Range(1, 20))
      ->capture_default_str();
  app.add_flag("--noise", sim_opt.noise, "add the plant file's Gaussian sensor noise");
  app.add_option("--seed", sim_opt.seed, "noise seed")->capture_default_str();
  std::vector<std::string> pushes;
  bool ball = false;
  app.add_option("--push", pushes,
                 "impulse on the torso, TIME:IX:IY (s, N·s, world), applied over 10 ms; repeatable");
  app.add_flag("--ball", ball, "pushes throw the scene's 5 kg ball with momentum IX:IY instead of a force");
  CLI11_PARSE(app, argc, argv);
  for (const std::string& p : pushes) {
    hqp::sim::Push push;
    double t = 0, ix = 0, iy = 0;
    char tail = 0;
    if (std::sscanf(p.c_str(), "%lf:%lf:%lf%c", &t, &ix, &iy, &tail) != 3 || t < 0) {
      std::fprintf(stderr, "hqp_sim: --push '%s': expected TIME:IX:IY, e.g. 1.0:10:0\n", p.c_str());
      return 2;
    }
    push.time = t;
    push.impulse = Eigen::Vector3d(ix, iy, 0.0);
    push.ball = ball;
    run.pushes.push_back(push);
  }

  try {
    hqp::sim::Simulation sim(sim_opt);
    std::unique_ptr<hqp::sim::Driver> driver;
    if (driver_name == "controller") {
      driver = hqp::sim::makeBalanceController(controller_config, solver == "wqp");
      if (!driver) {
        std::fprintf(stderr, "hqp_sim: this build has no balance controller; use --driver pd\n");
        return 2;
      }
    } else {
      driver = hqp::sim::makeJointPdDriver(sim);
    }
    std::printf("hqp_sim: scenario %s, %.1f s, driver %s%s\n", run.scenario.c_str(), run.duration, driver->name(),
                sim_opt.noise ? ", sensor noise on" : "");
    const hqp::sim::RunSummary r = hqp::sim::runScenario(sim, *driver, run);
    const double deg = 180.0 / M_PI;
    std::printf("\nsummary (%s, %s)\n", run.scenario.c_str(), r.driver.c_str());
    if (r.fell) {
      std::printf("  result             : FELL at t = %.3f s (%s)\n", r.fall_time, r.fall_reason.c_str());
    } else {
      std::printf("  result             : standing after %.2f s (no fall)\n", r.duration);
    }
    std::printf("  max torso pitch    : %.2f deg\n", r.max_abs_pitch * deg);
    std::printf("  max torso roll     : %.2f deg\n", r.max_abs_roll * deg);
    std::printf("  min torso height   : %.4f m\n", r.min_torso_height);
    std::printf("  CoM x excursion    : %+.1f .. %+.1f mm\n", r.com_x_min * 1e3, r.com_x_max * 1e3);
    for (int c = 0; c < hqp::sim::kContacts; ++c) {
      std::printf("  %s CoP (sole frame) : x %+.1f .. %+.1f mm, y %+.1f .. %+.1f mm\n", c == 0 ? "left " : "right",
                  r.cop_min[c].x() * 1e3, r.cop_max[c].x() * 1e3, r.cop_min[c].y() * 1e3, r.cop_max[c].y() * 1e3);
    }
    std::printf("  real-time factor   : %.1f (%.2f s wall for %.2f s simulated%s)\n", r.real_time_factor, r.wall_time,
                r.duration, r.video_path.empty() ? "" : ", video excluded");
    std::printf("  %s time : mean %.1f us, max %.1f us, 99.9%% %.1f us\n",
                driver_name == "controller" ? "controller" : "driver    ", r.tick_mean_us, r.tick_max_us,
                r.tick_p999_us);
    if (ball) std::printf("  ball impulse       : %.2f %.2f %.2f N·s delivered (ball momentum lost)\n", r.ball_impulse.x(), r.ball_impulse.y(), r.ball_impulse.z());
    if (r.feet_touch_ticks > 0) std::printf("  feet touching      : %.3f s (the F/T CoP includes foot-on-foot forces then)\n", r.feet_touch_ticks * sim.controlDt());
    if (r.safe_mode_ticks > 0) std::printf("  safe-mode ticks    : %ld\n", r.safe_mode_ticks);
    if (!r.csv_path.empty()) std::printf("  log                : %s\n", r.csv_path.c_str());
    if (!r.video_path.empty()) std::printf("  video              : %s\n", r.video_path.c_str());
    return r.fell ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hqp_sim: %s\n", e.what());
    return 2;
  }
}
