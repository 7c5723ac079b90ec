// A Lees-Edwards cell sheared past wraps of its offset (the images' shift
// goes back from L_x to 0): a wrap is only a relabelling of the same
// images, so the step that wraps, and the one after it, must look like any
// other step of the run. The 2D and 3D tests (test_shear, test_shear3)
// record each step's observables and hand them here.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace cdtest {

struct WrapStep {
  double offset = 0;         // after the step, in [0, L_x)
  double contacts = 0;       // rows carrying a force
  double max_overlap = 0;    // of a length: overlap_limit is in the same unit
  double sxy = 0, syy = 0;   // contact stress
  double kinetic = 0;        // kinetic energy
};

// From step `settle` on: the steps whose offset came back (a wrap), at
// least `min_wraps` of them; at each and at the next, every step-to-step
// change (contacts, sigma_xy, sigma_yy, kinetic energy) and the overlap no
// larger than 1.5 times the largest of the steps that do not wrap. A wrap
// that lost or doubled the contacts through the sheared boundary, or moved
// the images by another length than L_x, changes them by far more (a lost
// layer of contacts is ~1/sqrt(N) of them at once and opens overlaps of the
// order of a step's approach on the next steps).
inline void expect_wraps_continuous(const std::vector<WrapStep>& s, std::size_t settle, int min_wraps,
                                    double overlap_limit, const std::string& what) {
  std::vector<std::size_t> wraps;
  for (std::size_t k = settle; k < s.size(); ++k)
    if (s[k].offset < s[k - 1].offset) wraps.push_back(k);
  ASSERT_GE(static_cast<int>(wraps.size()), min_wraps) << what << ": the offset must wrap";
  const auto near_wrap = [&](std::size_t k) {
    return std::any_of(wraps.begin(), wraps.end(), [&](std::size_t w) { return k == w || k == w + 1; });
  };
  struct Q {
    const char* name;
    double WrapStep::*m;
    bool change;  // the step-to-step change, else the value
  };
  const Q qs[] = {{"contacts", &WrapStep::contacts, true}, {"sigma_xy", &WrapStep::sxy, true},
                  {"sigma_yy", &WrapStep::syy, true},      {"kinetic energy", &WrapStep::kinetic, true},
                  {"max overlap", &WrapStep::max_overlap, false}};
  for (const Q& q : qs) {
    const auto value = [&](std::size_t k) {
      return q.change ? std::abs(s[k].*q.m - s[k - 1].*q.m) : s[k].*q.m;
    };
    double normal = 0, at_wrap = 0;
    for (std::size_t k = settle; k < s.size(); ++k) {
      if (near_wrap(k))
        at_wrap = std::max(at_wrap, value(k));
      else
        normal = std::max(normal, value(k));
    }
    std::printf("[ %s ] %zu wraps; largest %s%s: %.4g at a wrap, %.4g elsewhere\n", what.c_str(), wraps.size(),
                q.change ? "change of " : "", q.name, at_wrap, normal);
    EXPECT_LE(at_wrap, 1.5 * normal) << what << ": " << q.name << " jumps at a wrap";
  }
  // And at every step: overlaps below overlap_limit (the callers: 1 % of
  // the smallest grain's diameter, the limit cdsim warns at; a wrong image
  // opens overlaps that last several steps, past the two compared above).
  for (std::size_t k = settle; k < s.size(); ++k)
    ASSERT_LT(s[k].max_overlap, overlap_limit) << what << ": step " << k;
}

}  // namespace cdtest
