#include "tofguard/risk/user_presence.hpp"

#include <algorithm>
#include <string>

#include "tofguard/risk_t.hpp"

namespace tofguard::risk {

std::optional<FrameFinding> user_not_where_modelled(const discrepancy_t& frame,
                                                    const OccupantSettings& occupant) {
  int64_t modelled = 0;
  int64_t missing = 0;
  std::string regions;  // the regions mostly missing, head to feet
  const size_t n =
      std::min(frame.body_region_modelled_pixels.size(), frame.body_region_missing_pixels.size());
  for (size_t k = 0; k < n && k < frame.body_region.size(); ++k) {
    modelled += frame.body_region_modelled_pixels[k];
    missing += frame.body_region_missing_pixels[k];
    if (2 * frame.body_region_missing_pixels[k] > frame.body_region_modelled_pixels[k]) {
      regions += (regions.empty() ? "" : ", ") + frame.body_region[k];
    }
  }
  if (modelled < occupant.presence_min_modelled_pixels) return std::nullopt;
  const double fraction = static_cast<double>(missing) / static_cast<double>(modelled);
  if (!(fraction > occupant.presence_max_missing_fraction)) return std::nullopt;
  FrameFinding f;
  f.cause = risk_t::CAUSE_UNCLASSIFIED;
  f.score = fraction;
  f.threshold = occupant.presence_max_missing_fraction;
  f.detail =
      "the user is not where the occupant model seats them (missing fraction): " + fixed(100 * fraction, 0) +
      " % of the " + std::to_string(modelled) + " modelled user pixels see farther than the envelope" +
      (regions.empty() ? std::string() : " (mostly missing: " + regions + ")") +
      "; an empty chair or a user who has slid or fallen";
  return f;
}

}  // namespace tofguard::risk
