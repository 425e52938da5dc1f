// hqp_random_urdf: writes a random kinematic tree as URDF, for cross-checks of
// the generated models against MuJoCo (which loads the same URDF).
//   hqp_random_urdf --seed <k> -o <file.urdf> [--fixed-base] [--min-links 10] [--max-links 20]
// The same seed gives the same file on every machine: the random numbers come
// from std::mt19937_64 (fully specified by the standard) turned into doubles
// here, not through the library's distributions (whose output is unspecified).
//
// Inertias are diagonal in the link frame with an <inertial> origin that has no
// rpy: MuJoCo stores every body inertia in principal axes and finds them for a
// full tensor by an iterative eigen-decomposition, which limits agreement with an
// exact model to ~1e-9. With diagonal tensors MuJoCo keeps them exactly. Fixed
// joints still give our fused bodies full tensors, which is fine: MuJoCo gets the
// un-fused links and fuses them itself.

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

class Random {
 public:
  explicit Random(std::uint64_t seed) : rng_(seed) {}
  double uniform(double lo, double hi) {   // [lo, hi)
    const double u = static_cast<double>(rng_() >> 11) * 0x1.0p-53;
    return lo + (hi - lo) * u;
  }
  int integer(int lo, int hi) {   // [lo, hi]
    return lo + static_cast<int>(rng_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool chance(double p) { return uniform(0, 1) < p; }

 private:
  std::mt19937_64 rng_;
};

std::string num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string vec(double a, double b, double c) { return num(a) + " " + num(b) + " " + num(c); }

// Three draws in a fixed order (the order of function arguments is unspecified).
std::string randomVec(Random& rnd, double lo0, double hi0, double lo1, double hi1, double lo2, double hi2) {
  const double a = rnd.uniform(lo0, hi0);
  const double b = rnd.uniform(lo1, hi1);
  const double c = rnd.uniform(lo2, hi2);
  return vec(a, b, c);
}

struct Link {
  int parent = -1;
  std::string joint_type;   // to the parent
  bool massless = false;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a random kinematic tree as URDF."};
  std::uint64_t seed = 0;
  std::string out_path;
  bool fixed_base = false;
  int min_links = 10, max_links = 20;
  app.add_option("--seed", seed, "random seed")->required();
  app.add_option("-o,--output", out_path, "URDF file to write")->required();
  app.add_flag("--fixed-base", fixed_base, "weld the root link to the world (default: floating joint)");
  app.add_option("--min-links", min_links, "fewest links")->check(CLI::Range(2, 1000));
  app.add_option("--max-links", max_links, "most links")->check(CLI::Range(2, 1000));
  CLI11_PARSE(app, argc, argv);
  if (max_links < min_links) {
    std::cerr << "--max-links < --min-links\n";
    return 1;
  }

  Random rnd(seed);
  const int n = rnd.integer(min_links, max_links);
  // Deep chains and bushy nodes both: extend the last link half of the time,
  // otherwise branch from any earlier one.
  std::vector<Link> links(n);
  for (int i = 1; i < n; ++i) {
    links[i].parent = rnd.chance(0.5) ? i - 1 : rnd.integer(0, i - 1);
    const double t = rnd.uniform(0, 1);
    links[i].joint_type = t < 0.4 ? "revolute" : t < 0.6 ? "continuous" : t < 0.8 ? "prismatic" : "fixed";
  }
  // Some fixed leaves carry no <inertial> (sensor frames); moving links always have mass.
  std::vector<bool> has_child(n, false);
  for (int i = 1; i < n; ++i) has_child[links[i].parent] = true;
  for (int i = 1; i < n; ++i) {
    links[i].massless = links[i].joint_type == "fixed" && !has_child[i] && rnd.chance(0.5);
  }

  const double pi = 3.14159265358979323846;
  std::ostringstream o;
  o << "<?xml version=\"1.0\"?>\n"
    << "<!-- Written by hqp_random_urdf --seed " << seed << (fixed_base ? " --fixed-base" : "") << " -->\n"
    << "<robot name=\"random_tree_" << seed << "\">\n"
    << "  <mujoco>\n"
    << "    <compiler discardvisual=\"true\" fusestatic=\"true\" inertiafromgeom=\"false\""
       " balanceinertia=\"false\"/>\n"
    << "  </mujoco>\n";
  if (!fixed_base) {
    o << "  <link name=\"world\"/>\n"
      << "  <joint name=\"root_free\" type=\"floating\">\n"
      << "    <parent link=\"world\"/>\n    <child link=\"link_0\"/>\n  </joint>\n";
  }
  for (int i = 0; i < n; ++i) {
    o << "  <link name=\"link_" << i << "\">\n";
    if (!links[i].massless) {
      // Principal moments of a solid box, so the triangle inequality holds.
      const double m = rnd.uniform(0.5, 5.0);
      const double a = rnd.uniform(0.05, 0.4), b = rnd.uniform(0.05, 0.4), c = rnd.uniform(0.05, 0.4);
      o << "    <inertial>\n"
        << "      <origin xyz=\"" << randomVec(rnd, -0.1, 0.1, -0.1, 0.1, -0.1, 0.1)
        << "\" rpy=\"0 0 0\"/>\n"
        << "      <mass value=\"" << num(m) << "\"/>\n"
        << "      <inertia ixx=\"" << num(m * (b * b + c * c) / 12) << "\" iyy=\"" << num(m * (a * a + c * c) / 12)
        << "\" izz=\"" << num(m * (a * a + b * b) / 12) << "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>\n"
        << "    </inertial>\n";
    }
    o << "  </link>\n";
  }
  for (int i = 1; i < n; ++i) {
    const Link& l = links[i];
    // Joint names do not follow link numbers, so sorting by name reorders siblings.
    const char tag = static_cast<char>('a' + rnd.integer(0, 25));
    o << "  <joint name=\"" << tag << "_joint_" << i << "\" type=\"" << l.joint_type << "\">\n"
      << "    <parent link=\"link_" << l.parent << "\"/>\n    <child link=\"link_" << i << "\"/>\n"
      << "    <origin xyz=\"" << randomVec(rnd, -0.3, 0.3, -0.3, 0.3, -0.3, 0.3)
      << "\" rpy=\"" << randomVec(rnd, -pi, pi, -pi / 2, pi / 2, -pi, pi) << "\"/>\n";
    if (l.joint_type != "fixed") {
      // Random direction and length: the generator must normalize.
      double x = 0, y = 0, z = 0, norm = 0;
      while (norm < 0.1) {
        x = rnd.uniform(-1, 1);
        y = rnd.uniform(-1, 1);
        z = rnd.uniform(-1, 1);
        norm = std::sqrt(x * x + y * y + z * z);
      }
      const double s = rnd.uniform(0.5, 2.0) / norm;
      o << "    <axis xyz=\"" << vec(s * x, s * y, s * z) << "\"/>\n";
      const double effort = rnd.uniform(10, 200), velocity = rnd.uniform(1, 20);
      if (l.joint_type == "revolute") {
        o << "    <limit lower=\"" << num(rnd.uniform(-2.5, -0.5)) << "\" upper=\"" << num(rnd.uniform(0.5, 2.5))
          << "\" effort=\"" << num(effort) << "\" velocity=\"" << num(velocity) << "\"/>\n";
      } else if (l.joint_type == "prismatic") {
        o << "    <limit lower=\"" << num(rnd.uniform(-0.3, -0.05)) << "\" upper=\"" << num(rnd.uniform(0.05, 0.3))
          << "\" effort=\"" << num(effort) << "\" velocity=\"" << num(velocity) << "\"/>\n";
      } else {
        o << "    <limit effort=\"" << num(effort) << "\" velocity=\"" << num(velocity) << "\"/>\n";
      }
      o << "    <dynamics damping=\"" << num(rnd.uniform(0, 0.5)) << "\" friction=\"" << num(rnd.uniform(0, 0.3))
        << "\"/>\n";
    }
    o << "  </joint>\n";
  }
  o << "</robot>\n";

  std::ofstream out(out_path, std::ios::binary | std::ios::trunc);
  out << o.str();
  if (!out) {
    std::cerr << out_path << ": cannot write the file\n";
    return 1;
  }
  return 0;
}
