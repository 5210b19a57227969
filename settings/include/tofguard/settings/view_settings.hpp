#pragma once
// What tofguard-view needs from the deployment config.
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/settings/discrepancy_settings.hpp"

namespace tofguard::settings {

// The protective and warning fields to draw (docs/safety-chain.md,
// "Protective fields"): S with the arm at rest and the warning margin
// beyond it, metres (protective_at_rest_m <= 0: none drawn). On a frame
// whose verdict is an unknown object, that verdict's threshold (the S of
// its frame) is drawn instead.
struct FieldSizes {
  double protective_at_rest_m = 0;
  double warning_margin_m = 0;
};

struct ViewSettings {
  LcmSettings lcm;
  ChannelNames channels;
  // The discrepancy rules, to colour the discrepancy image as
  // tofguard-discrepancy judges it.
  discrepancy::DiscrepancySettings discrepancy;
  // renderer.far_m: the depth images' full scale, metres.
  double far_m = 0;
  // camera.rate_hz: an exported video's frame rate.
  double camera_rate_hz = 0;
  // The fields drawn on the camera panel: S with the arm at rest (from
  // risk.field and the camera's rate) and risk.field.warning_margin_m.
  FieldSizes fields;
};

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::view::FieldSizes, ...).
namespace tofguard::view {
using settings::FieldSizes;
using settings::ViewSettings;
}  // namespace tofguard::view
