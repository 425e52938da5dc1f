#pragma once
// The simulated plant's parameters (robots/walker3/plant.yaml): joint friction, rotor inertia,
// torque constants, sensor sites and noise. Read by the MJCF generator at build time and by the
// simulation at run time. Not real-time code (yaml-cpp, exceptions).

#include <yaml-cpp/yaml.h>

#include <array>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace hqp::sim {

struct JointPlant {
  double coulomb = 0.0;          // N·m, breakaway friction (MJCF frictionloss)
  double viscous = 0.0;          // N·m·s/rad (MJCF damping)
  double armature = 0.0;         // kg·m², reflected rotor inertia
  double torque_constant = 1.0;  // N·m/A, joint side
};

struct ForceTorqueSite {
  std::string name;   // sensor name prefix (name_force, name_torque)
  std::string frame;  // URDF link of the sensor frame
  std::string foot;   // URDF link whose collision geometry is the sole plate
  std::string sole;   // URDF link of the sole frame (the plate's massless body)
};

struct SensorNoise {
  // White noise (standard deviation per sample).
  double joint_position = 0, joint_velocity = 0, imu_orientation = 0, gyro = 0, accelerometer = 0,
         force = 0, torque = 0;
  // IMU biases, IMU frame: each axis starts at N(0, bias²) and then walks by drift·√dt·N(0, 1)
  // per step (rad/s and rad/s/√s; m/s² and m/s²/√s).
  double gyro_bias = 0, gyro_bias_drift = 0, accelerometer_bias = 0, accelerometer_bias_drift = 0;
  double imu_yaw_drift = 0;  // rad/s, the orientation output turns about world z at this rate
};

struct PlantConfig {
  std::map<std::string, JointPlant> joints;  // by full URDF joint name
  std::array<double, 2> solreffriction{0.02, 1.0};
  std::array<double, 5> solimpfriction{0.9, 0.95, 0.001, 0.5, 2.0};
  int noslip_iterations = 0;  // MuJoCo's post-pass that removes the soft contacts' tangential creep
  std::string imu_link;
  std::vector<ForceTorqueSite> force_torque;
  SensorNoise noise;

  // Plant of a URDF joint: "l_knee" uses the key "l_knee" if present, else "knee".
  const JointPlant& joint(const std::string& name) const {
    auto it = joints.find(name);
    if (it == joints.end() && name.size() > 2 && name[1] == '_') it = joints.find(name.substr(2));
    if (it == joints.end()) throw std::runtime_error("plant file: no entry for joint '" + name + "'");
    return it->second;
  }
};

namespace plant_detail {

inline double number(const YAML::Node& n, const std::string& path, const std::string& file) {
  if (!n || !n.IsScalar()) throw std::runtime_error(file + ": missing or invalid number '" + path + "'");
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(file + ": '" + path + "' is not a number");
  }
}

inline std::string text(const YAML::Node& n, const std::string& path, const std::string& file) {
  if (!n || !n.IsScalar()) throw std::runtime_error(file + ": missing or invalid string '" + path + "'");
  return n.as<std::string>();
}

template <std::size_t N>
std::array<double, N> numbers(const YAML::Node& n, const std::string& path, const std::string& file) {
  if (!n || !n.IsSequence() || n.size() != N) {
    throw std::runtime_error(file + ": '" + path + "' must be a list of " + std::to_string(N) + " numbers");
  }
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = number(n[i], path, file);
  return out;
}

}  // namespace plant_detail

// Throws std::runtime_error naming the file and the key on a missing or invalid entry.
inline PlantConfig loadPlantConfig(const std::string& path) {
  using plant_detail::number;
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("cannot read plant file " + path + ": " + e.what());
  }
  PlantConfig c;
  const YAML::Node joints = root["joints"];
  if (!joints || !joints.IsMap()) throw std::runtime_error(path + ": missing map 'joints'");
  for (const auto& kv : joints) {
    const std::string name = kv.first.as<std::string>();
    const std::string p = "joints." + name + ".";
    JointPlant j;
    j.coulomb = number(kv.second["coulomb"], p + "coulomb", path);
    j.viscous = number(kv.second["viscous"], p + "viscous", path);
    j.armature = number(kv.second["armature"], p + "armature", path);
    j.torque_constant = number(kv.second["torque_constant"], p + "torque_constant", path);
    if (j.coulomb < 0 || j.viscous < 0 || j.armature < 0 || !(j.torque_constant > 0)) {
      throw std::runtime_error(path + ": joint '" + name + "' needs coulomb, viscous, armature >= 0 and torque_constant > 0");
    }
    c.joints[name] = j;
  }
  const YAML::Node fs = root["friction_solver"];
  if (fs) {
    c.solreffriction = plant_detail::numbers<2>(fs["solreffriction"], "friction_solver.solreffriction", path);
    c.solimpfriction = plant_detail::numbers<5>(fs["solimpfriction"], "friction_solver.solimpfriction", path);
  }
  const YAML::Node cs = root["contact_solver"];
  if (cs && cs["noslip_iterations"]) {
    const double n = number(cs["noslip_iterations"], "contact_solver.noslip_iterations", path);
    if (!(n >= 0 && n <= 1000) || n != static_cast<int>(n)) {
      throw std::runtime_error(path + ": 'contact_solver.noslip_iterations' must be an integer in [0, 1000]");
    }
    c.noslip_iterations = static_cast<int>(n);
  }
  const YAML::Node sensors = root["sensors"];
  if (!sensors) throw std::runtime_error(path + ": missing map 'sensors'");
  c.imu_link = plant_detail::text(sensors["imu"], "sensors.imu", path);
  const YAML::Node ft = sensors["force_torque"];
  if (!ft || !ft.IsSequence()) throw std::runtime_error(path + ": 'sensors.force_torque' must be a list");
  for (std::size_t i = 0; i < ft.size(); ++i) {
    const std::string p = "sensors.force_torque[" + std::to_string(i) + "].";
    c.force_torque.push_back({plant_detail::text(ft[i]["name"], p + "name", path),
                              plant_detail::text(ft[i]["frame"], p + "frame", path),
                              plant_detail::text(ft[i]["foot"], p + "foot", path),
                              plant_detail::text(ft[i]["sole"], p + "sole", path)});
  }
  const YAML::Node noise = root["noise"];
  if (noise) {
    c.noise.joint_position = number(noise["joint_position"], "noise.joint_position", path);
    c.noise.joint_velocity = number(noise["joint_velocity"], "noise.joint_velocity", path);
    c.noise.imu_orientation = number(noise["imu_orientation"], "noise.imu_orientation", path);
    c.noise.gyro = number(noise["gyro"], "noise.gyro", path);
    c.noise.accelerometer = number(noise["accelerometer"], "noise.accelerometer", path);
    c.noise.force = number(noise["force"], "noise.force", path);
    c.noise.torque = number(noise["torque"], "noise.torque", path);
    // Optional: IMU biases and yaw drift (absent = none).
    auto optional = [&](const char* key, double& v) {
      if (noise[key]) v = number(noise[key], std::string("noise.") + key, path);
      if (!(v >= 0)) throw std::runtime_error(path + ": 'noise." + key + "' must be >= 0");
    };
    optional("gyro_bias", c.noise.gyro_bias);
    optional("gyro_bias_drift", c.noise.gyro_bias_drift);
    optional("accelerometer_bias", c.noise.accelerometer_bias);
    optional("accelerometer_bias_drift", c.noise.accelerometer_bias_drift);
    optional("imu_yaw_drift", c.noise.imu_yaw_drift);
  }
  return c;
}

}  // namespace hqp::sim
