#pragma once
// Contact state of one foot from its sole-frame normal force (docs/controller.md, "Contact
// state"): a hysteresis latch (in contact above contact_on, out below contact_threshold, so a
// load near the threshold does not re-latch the foot every tick) and a confidence that ramps
// from 0 at contact_threshold to 1 at contact_full. The state estimator multiplies the
// confidence by the foot's stationarity to weight it as a zero-velocity measurement, and sets
// the moving flag (a loaded foot that moves in the world: slip, or a moving support).
// No heap, no exceptions; a NaN force leaves the foot out of contact with zero confidence.

#include <algorithm>

namespace hqp::tasks {

struct ContactParameters {
  double contact_threshold = 30.0;  // N, out of contact below this normal force
  double contact_on = 0.0;          // N, into contact above this; ≤ contact_threshold: no hysteresis
  double contact_full = 0.0;        // N, confidence 1 from here; ≤ contact_on: a step at the latch
};

class ContactEstimator {
 public:
  void reset() noexcept {
    in_contact_ = false;
    confidence_ = 0.0;
    moving_ = false;
  }

  void update(double fz, const ContactParameters& p) noexcept {
    const double on = std::max(p.contact_on, p.contact_threshold);
    if (!(fz == fz)) {  // NaN
      reset();
      return;
    }
    if (in_contact_) in_contact_ = fz > p.contact_threshold;
    else in_contact_ = fz > on;
    const double full = p.contact_full;
    if (!in_contact_) confidence_ = 0.0;
    else if (full <= on) confidence_ = 1.0;
    else confidence_ = std::clamp((fz - p.contact_threshold) / (full - p.contact_threshold), 0.0, 1.0);
  }

  void setMoving(bool m) noexcept { moving_ = m; }

  bool inContact() const noexcept { return in_contact_; }
  double confidence() const noexcept { return confidence_; }  // [0, 1]
  bool moving() const noexcept { return moving_; }

 private:
  bool in_contact_ = false;
  double confidence_ = 0.0;
  bool moving_ = false;
};

}  // namespace hqp::tasks
