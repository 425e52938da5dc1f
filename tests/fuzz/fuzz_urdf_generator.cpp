// libFuzzer harness: the URDF generator (tools/urdf2model/generate.hpp, the code of
// hqp_urdf2model) on arbitrary text, fixed and floating base (docs/fuzzing.md). It never
// crashes; it either throws UrdfError with one line naming an element (a link, a joint, an
// XML line, urdfdom's message, <robot>, an option), or returns a model that satisfies the
// contract of docs/generated-model.md, checked here: every number finite, masses > 0,
// inertias symmetric positive definite, unit axes, lower ≤ upper, effort and velocity > 0,
// rotations orthonormal, parents before children, q/v indices consistent.
#include <string>

#include "fuzz_common.hpp"
#include "urdf2model/generate.hpp"

namespace {

bool startsWith(const std::string& s, const char* p) { return s.rfind(p, 0) == 0; }

void checkModel(const hqp::tools::Model& m) {
  HQP_FUZZ_CHECK(!m.bodies.empty());
  const int fb = m.floating_base ? 1 : 0;
  HQP_FUZZ_CHECK(m.nj == static_cast<int>(m.bodies.size()) - fb);
  HQP_FUZZ_CHECK(m.nq == m.nj + 7 * fb && m.nv == m.nj + 6 * fb);
  HQP_FUZZ_CHECK(std::isfinite(m.total_mass) && m.total_mass > 0);
  for (int i = 0; i < static_cast<int>(m.bodies.size()); ++i) {
    const hqp::tools::Body& b = m.bodies[static_cast<size_t>(i)];
    HQP_FUZZ_CHECK(b.parent >= -1 && b.parent < i);
    HQP_FUZZ_CHECK(std::isfinite(b.mass) && b.mass > 0);
    HQP_FUZZ_CHECK(b.com.allFinite() && b.inertia.allFinite());
    HQP_FUZZ_CHECK((b.inertia - b.inertia.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * b.inertia.cwiseAbs().maxCoeff());
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(b.inertia).eigenvalues();
    HQP_FUZZ_CHECK2(ev(0) > -1e-9 * ev(2), ev(0), ev(2));
    HQP_FUZZ_CHECK(b.placement.p.allFinite() && b.placement.R.allFinite());
    HQP_FUZZ_CHECK((b.placement.R * b.placement.R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9);
    if (b.type == "Free") continue;
    HQP_FUZZ_CHECK2(b.axis.allFinite() && std::abs(b.axis.norm() - 1.0) < 1e-12, b.axis.norm(), 0.0);
    HQP_FUZZ_CHECK2(b.lower <= b.upper, b.lower, b.upper);
    HQP_FUZZ_CHECK(!std::isnan(b.lower) && !std::isnan(b.upper));
    HQP_FUZZ_CHECK2(b.effort > 0 && b.velocity > 0, b.effort, b.velocity);
    HQP_FUZZ_CHECK(std::isfinite(b.damping) && std::isfinite(b.friction));
  }
  for (const hqp::tools::Frame& fr : m.frames) {
    HQP_FUZZ_CHECK(fr.body >= -1 && fr.body < static_cast<int>(m.bodies.size()));
    HQP_FUZZ_CHECK(fr.placement.p.allFinite() && fr.placement.R.allFinite());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string xml(reinterpret_cast<const char*>(data), size);
  for (int floating = 0; floating < 2; ++floating) {
    hqp::tools::Options opt;
    opt.floating_base = floating != 0;
    hqp::tools::Model model;
    try {
      const std::string header = hqp::tools::generate(xml, opt, "", &model);
      HQP_FUZZ_CHECK(!header.empty());
      checkModel(model);
    } catch (const hqp::tools::UrdfError& e) {
      const std::string w = e.what();
      HQP_FUZZ_CHECK(!w.empty() && w.find('\n') == std::string::npos);
      const bool named = startsWith(w, "joint '") || startsWith(w, "link '") || startsWith(w, "line ") ||
                         startsWith(w, "urdfdom: ") || startsWith(w, "<robot>") || startsWith(w, "no <robot>") ||
                         startsWith(w, "the robot has no") || startsWith(w, "--namespace");
      if (!named) hqp::fuzz::fail(w.c_str());
    }
    // Any other exception escapes and is reported by libFuzzer as a crash.
  }
  return 0;
}
