#pragma once
// A sensor log: one CSV row per tick with everything SensorData holds (and, optionally, the
// current the controller commanded for it), written with 17 significant digits so that a
// replay feeds the controller bit-identical sensors. Set-up and tear-down time only (stdio,
// heap); never inside the tick.

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "walker3_firmware.hpp"

namespace hqp::firmware {

struct LogRow {
  Sensors sensors;
  Command command;  // zero if the log has no current columns
};

inline void writeSensorLogHeader(std::FILE* f, bool with_current) {
  std::fprintf(f, "time");
  for (const char* g : {"q", "dq"})
    for (int j = 0; j < kJoints; ++j) std::fprintf(f, ",%s_%s", g, Robot::bodies[j + 1].joint);
  std::fprintf(f, ",imu_qw,imu_qx,imu_qy,imu_qz,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z");
  for (const char* foot : {"l", "r"})
    for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"}) std::fprintf(f, ",%s_ft_%s", foot, c);
  if (with_current)
    for (int j = 0; j < kJoints; ++j) std::fprintf(f, ",i_%s", Robot::bodies[j + 1].joint);
  std::fputc('\n', f);
}

inline void writeSensorLogRow(std::FILE* f, const Sensors& s, const Command* cmd) {
  std::fprintf(f, "%.17g", s.time);
  for (int j = 0; j < kJoints; ++j) std::fprintf(f, ",%.17g", s.q[j]);
  for (int j = 0; j < kJoints; ++j) std::fprintf(f, ",%.17g", s.dq[j]);
  const auto& o = s.imu_orientation;
  std::fprintf(f, ",%.17g,%.17g,%.17g,%.17g", o.w(), o.x(), o.y(), o.z());
  for (int k = 0; k < 3; ++k) std::fprintf(f, ",%.17g", s.imu_gyro[k]);
  for (int k = 0; k < 3; ++k) std::fprintf(f, ",%.17g", s.imu_accel[k]);
  for (int c = 0; c < kContacts; ++c)
    for (int k = 0; k < 6; ++k) std::fprintf(f, ",%.17g", s.ft[static_cast<std::size_t>(c)][k]);
  if (cmd)
    for (int j = 0; j < kJoints; ++j) std::fprintf(f, ",%.17g", cmd->current[j]);
  std::fputc('\n', f);
}

constexpr int kSensorColumns = 1 + 2 * kJoints + 4 + 3 + 3 + 6 * kContacts;

// Reads a log written by writeSensorLog*; `has_current` tells whether it had the current
// columns. Returns an empty string or an error naming the file and line.
inline std::string readSensorLog(const std::string& path, std::vector<LogRow>& rows, bool& has_current) {
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return "cannot read " + path;
  std::string line;
  auto getLine = [&]() {
    line.clear();
    int ch;
    while ((ch = std::fgetc(f)) != EOF && ch != '\n') line.push_back(static_cast<char>(ch));
    return !(ch == EOF && line.empty());
  };
  getLine();  // header
  int columns = 1;
  for (char ch : line) columns += ch == ',';
  if (columns != kSensorColumns && columns != kSensorColumns + kJoints) {
    std::fclose(f);
    return path + ": header has " + std::to_string(columns) + " columns, expected " +
           std::to_string(kSensorColumns) + " or " + std::to_string(kSensorColumns + kJoints);
  }
  has_current = columns == kSensorColumns + kJoints;
  std::vector<double> v(static_cast<std::size_t>(columns));
  for (int lineno = 2; getLine(); ++lineno) {
    const char* p = line.c_str();
    for (int i = 0; i < columns; ++i) {
      char* end = nullptr;
      v[static_cast<std::size_t>(i)] = std::strtod(p, &end);
      if (end == p || (i + 1 < columns && *end != ',') || (i + 1 == columns && *end != '\0')) {
        std::fclose(f);
        return path + ":" + std::to_string(lineno) + ": column " + std::to_string(i + 1) + " is not a number";
      }
      p = end + 1;
    }
    LogRow r;
    const double* x = v.data();
    r.sensors.time = *x++;
    for (int j = 0; j < kJoints; ++j) r.sensors.q[j] = *x++;
    for (int j = 0; j < kJoints; ++j) r.sensors.dq[j] = *x++;
    r.sensors.imu_orientation.w() = x[0];
    r.sensors.imu_orientation.x() = x[1];
    r.sensors.imu_orientation.y() = x[2];
    r.sensors.imu_orientation.z() = x[3];
    x += 4;
    for (int k = 0; k < 3; ++k) r.sensors.imu_gyro[k] = *x++;
    for (int k = 0; k < 3; ++k) r.sensors.imu_accel[k] = *x++;
    for (int c = 0; c < kContacts; ++c)
      for (int k = 0; k < 6; ++k) r.sensors.ft[static_cast<std::size_t>(c)][k] = *x++;
    if (has_current)
      for (int j = 0; j < kJoints; ++j) r.command.current[j] = *x++;
    rows.push_back(r);
  }
  std::fclose(f);
  return {};
}

}  // namespace hqp::firmware
