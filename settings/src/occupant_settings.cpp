#include "tofguard/settings/occupant_settings.hpp"

namespace tofguard::settings {
namespace {

BodyRegionSettings read_region(YamlMap region, BodyRegion which) {
  BodyRegionSettings r;
  r.envelope_m = region.number("envelope_m", 0, 1);
  if (region.optional("clearance_m")) r.clearance_m = region.number("clearance_m", 0.001, 1);
  if (body_region_is_no_contact(which) && !r.clearance_m) {
    region.fail("clearance_m",
                "a clearance in metres (the head and the neck get a clearance, never a contact)");
  }
  region.finish();
  return r;
}

std::map<BodyRegion, BodyRegionSettings> read_regions(YamlMap regions) {
  std::map<BodyRegion, BodyRegionSettings> out;
  for (const std::string& name : regions.keys()) {
    const std::optional<BodyRegion> region = body_region_named(name);
    if (!region) regions.fail(name, "a body region (one of " + body_region_names() + ")");
    out[*region] = read_region(regions.map(name), *region);
  }
  for (const BodyRegion region : all_body_regions()) {
    if (!out.count(region)) {
      regions.fail(body_region_name(region),
                   "every body region with its envelope_m (a region without a rule would have none)");
    }
  }
  return out;
}

}  // namespace

std::optional<OccupantSettings> read_occupant_settings(std::optional<YamlMap> section) {
  if (!section) return std::nullopt;
  OccupantSettings o;
  o.urdf_path = section->existing_path("urdf");
  o.seated_on = section->string("seated_on");
  o.payload_kg = section->number("payload_kg", 0, 100);
  o.contact_force_factor = section->number("contact_force_factor", 1, 2);
  o.regions = read_regions(section->map("regions"));
  YamlMap presence = section->map("presence");
  o.presence_min_modelled_pixels = static_cast<int>(presence.integer("min_modelled_pixels", 1, 10000000));
  o.presence_max_missing_fraction = presence.number("max_missing_fraction", 0.01, 0.99);
  presence.finish();
  section->finish();
  return o;
}

}  // namespace tofguard::settings
