#pragma once
// Is the wheelchair's user where the occupant model seats them
// (docs/safety-chain.md, "The user")? The model is what lets the chain
// serve a user within the arm's reach; a chair that is empty, or a user
// who has slid down or fallen, is a scene the model no longer describes,
// and the monitor says so instead of judging the arm against a person who
// is not there. Pure logic: no LCM, no clocks.
#include <optional>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/settings/occupant_settings.hpp"

namespace tofguard::risk {

// The finding (CAUSE_UNCLASSIFIED, debounced as the frame rules') when the
// frame shows at least occupant.presence_min_modelled_pixels of the
// modelled user and more than presence_max_missing_fraction of them see
// farther than their region's envelope (discrepancy_t's
// body_region_modelled_pixels and body_region_missing_pixels); nullopt
// otherwise, and for a frame that shows too little of the user to say.
std::optional<FrameFinding> user_not_where_modelled(const discrepancy_t& frame,
                                                    const OccupantSettings& occupant);

}  // namespace tofguard::risk
