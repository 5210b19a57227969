#include "tofguard/discrepancy/discrepancy_image.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "tofguard/common/demand.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/discrepancy/arm_distance.hpp"
#include "tofguard/discrepancy/occupant_shapes.hpp"

namespace tofguard::discrepancy {
namespace {

// Counts of I_dis values in whole millimetres, clamped to +-kHistogramMm
// (medians and percentiles of larger discrepancies saturate there): a
// median from counts costs one pass over 8191 bins instead of sorting.
constexpr int kHistogramMm = 4095;

// Reused from frame to frame (DisHistograms): a histogram keeps the range of
// bins it has touched, and clearing, merging and ranking go over that range
// only (a link's values span tens of bins, not 8191), so a frame neither
// zeroes nor reads the whole arrays (at 30 Hz, with the caches cold, the
// zeroing alone was 7 % of compute_discrepancy).
class Histogram {
 public:
  Histogram() : bins_(kBins, 0) {}
  // Back to no values (zeroing the touched bins only).
  void clear() {
    if (lo_ <= hi_) std::fill(bins_.begin() + lo_, bins_.begin() + hi_ + 1, 0);
    lo_ = kBins;
    hi_ = -1;
    count_ = 0;
  }
  void add(int value_mm) {
    const int bin = std::clamp(value_mm, -kHistogramMm, kHistogramMm) + kHistogramMm;
    bins_[bin]++;
    touch(bin);
    ++count_;
  }
  void add(const Histogram& other) {
    for (int i = other.lo_; i <= other.hi_; ++i) bins_[i] += other.bins_[i];
    if (other.lo_ <= other.hi_) {
      touch(other.lo_);
      touch(other.hi_);
    }
    count_ += other.count_;
  }
  int64_t count() const { return count_; }
  // The value of rank `k` (0-based) in ascending order.
  int value_at_rank(int64_t k) const {
    int64_t seen = 0;
    for (int i = lo_; i <= hi_; ++i) {
      seen += bins_[i];
      if (seen > k) return i - kHistogramMm;
    }
    return kHistogramMm;
  }
  // The element at index size/2 of the sorted values (0 for none).
  float median() const { return count_ == 0 ? 0.0f : static_cast<float>(value_at_rank(count_ / 2)); }
  // The element at index floor(q*(size-1)).
  float quantile(double q) const {
    if (count_ == 0) return 0.0f;
    return static_cast<float>(
        value_at_rank(static_cast<int64_t>(std::floor(q * static_cast<double>(count_ - 1)))));
  }
  // Adds the counts of |value| to `abs`.
  void add_folded_to(Histogram* abs) const {
    for (int i = lo_; i <= hi_; ++i) {
      if (bins_[i] == 0) continue;
      const int folded = std::abs(i - kHistogramMm) + kHistogramMm;
      abs->bins_[folded] += bins_[i];
      abs->touch(folded);
    }
    abs->count_ += count_;
  }

 private:
  static constexpr int kBins = 2 * kHistogramMm + 1;
  void touch(int bin) {
    lo_ = std::min(lo_, bin);
    hi_ = std::max(hi_, bin);
  }
  // Counts per millimetre (a frame has fewer than 2^31 pixels).
  std::vector<int32_t> bins_;
  int lo_ = kBins;  // the touched bins: [lo_, hi_], none when lo_ > hi_
  int hi_ = -1;
  int64_t count_ = 0;
};

bool same_intrinsics(const depth_image_t& a, const depth_image_t& b) {
  constexpr double kTolerancePx = 1e-3;
  return std::abs(a.fx - b.fx) <= kTolerancePx && std::abs(a.fy - b.fy) <= kTolerancePx &&
         std::abs(a.cx - b.cx) <= kTolerancePx && std::abs(a.cy - b.cy) <= kTolerancePx;
}

// "" when the three messages describe the same frame, else why not.
std::string mismatch_reason(const depth_image_t& camera, const depth_image_t& rendered,
                            const link_labels_t& labels) {
  std::ostringstream why;
  if (rendered.width != camera.width || rendered.height != camera.height) {
    why << "rendered frame is " << rendered.width << "x" << rendered.height << ", camera frame "
        << camera.width << "x" << camera.height;
  } else if (labels.width != camera.width || labels.height != camera.height) {
    why << "labels are " << labels.width << "x" << labels.height << ", camera frame " << camera.width << "x"
        << camera.height;
  } else if (rendered.camera_id != camera.camera_id || labels.camera_id != camera.camera_id) {
    why << "camera_id: rendered '" << rendered.camera_id << "', labels '" << labels.camera_id << "', camera '"
        << camera.camera_id << "'";
  } else if (!same_intrinsics(camera, rendered)) {
    why << "rendered intrinsics fx " << rendered.fx << " fy " << rendered.fy << " cx " << rendered.cx
        << " cy " << rendered.cy << " differ from the camera's fx " << camera.fx << " fy " << camera.fy
        << " cx " << camera.cx << " cy " << camera.cy;
  }
  return why.str();
}

cv::Mat1b opened(const cv::Mat1b& mask, int radius_px) {
  if (radius_px <= 0) return mask;
  cv::Mat1b out;
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * radius_px + 1, 2 * radius_px + 1));
  cv::morphologyEx(mask, out, cv::MORPH_OPEN, kernel);
  return out;
}

// The opening of `mask` (a square of radius_px) in which neighbours belong
// together only on one surface: a pixel survives the erosion when every
// pixel of its square is in the mask and within jump_mm of its depth, and
// the dilation gives back the mask's pixels within jump_mm of a survivor in
// their square. A sliver of the arm's own edge seen a pixel or two wider
// than modelled, or a row of mixed pixels, touching a larger unexplained
// surface at another depth (a cart passing behind the arm) goes, as it
// would with nothing beside it; the surface itself stays. jump_mm <= 0:
// the plain opening.
cv::Mat1b opened_on_surfaces(const cv::Mat1b& mask, const int16_t* depth_mm, int radius_px, double jump_mm) {
  // No jump (silhouettes off, silhouette_jump_mm <= 0): the plain opening.
  if (radius_px <= 0 || jump_mm <= 0) return opened(mask, radius_px);
  const int width = mask.cols;
  const int height = mask.rows;
  const uint8_t* in = mask.ptr<uint8_t>();
  const auto same_surface = [&](int i, int j) {
    return in[j] != 0 && std::abs(depth_mm[j] - depth_mm[i]) <= jump_mm;
  };
  cv::Mat1b core(height, width, uint8_t{0});
  uint8_t* survivor = core.ptr<uint8_t>();
  for (int v = radius_px; v < height - radius_px; ++v) {
    for (int u = radius_px; u < width - radius_px; ++u) {
      const int i = v * width + u;
      if (in[i] == 0) continue;
      bool whole = true;
      for (int dv = -radius_px; dv <= radius_px && whole; ++dv) {
        for (int du = -radius_px; du <= radius_px && whole; ++du)
          whole = same_surface(i, i + dv * width + du);
      }
      survivor[i] = whole ? 255 : 0;
    }
  }
  cv::Mat1b out(height, width, uint8_t{0});
  uint8_t* kept = out.ptr<uint8_t>();
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const int i = v * width + u;
      if (in[i] == 0) continue;
      bool near_survivor = false;
      for (int dv = -radius_px; dv <= radius_px && !near_survivor; ++dv) {
        const int vn = v + dv;
        if (vn < 0 || vn >= height) continue;
        for (int du = -radius_px; du <= radius_px && !near_survivor; ++du) {
          const int un = u + du;
          if (un < 0 || un >= width) continue;
          const int j = vn * width + un;
          near_survivor = survivor[j] != 0 && std::abs(depth_mm[j] - depth_mm[i]) <= jump_mm;
        }
      }
      kept[i] = near_survivor ? 255 : 0;
    }
  }
  return out;
}

// How long compute_discrepancy's workers poll for its first call: far more
// than the checks and the silhouettes before it take (0.1 ms at 176x144).
constexpr std::chrono::microseconds kWorkersExpected{1000};

// ---- The stages of compute_discrepancy, in order ----

// Stage 1, label decoding: "" when every label value names a link or
// nothing (link_of_label, common/depth_frame.hpp), else why not (the first
// bad pixel). The later stages decode each pixel's label again: one lookup
// costs less than a per-pixel link buffer (see per_link_statistics on heap
// churn).
std::string check_labels(const link_labels_t& labels) {
  const int num_robot_links = labels.num_robot_links;
  const int num_links = labels.num_links;
  const int num_pixels = labels.width * labels.height;
  for (int i = 0; i < num_pixels; ++i) {
    const int l = labels.label[i];
    if (l == kLabelNothing || link_of_label(l, num_robot_links, num_links) >= 0 ||
        occupant_shape_of_label(l, labels.num_occupant_shapes) >= 0) {
      continue;
    }
    std::ostringstream why;
    why << "label[" << i << "]: expected " << kLabelNothing << ", " << kLabelRobotFirst << ".."
        << kLabelRobotFirst + num_robot_links - 1;
    if (labels.num_occupant_shapes > 0) {
      why << ", " << kLabelEnvironmentFirst << ".."
          << kLabelEnvironmentFirst + (num_links - num_robot_links) - 1 << " or " << kLabelOccupantFirst
          << ".." << kLabelOccupantFirst + labels.num_occupant_shapes - 1;
    } else {
      why << " or " << kLabelEnvironmentFirst << ".."
          << kLabelEnvironmentFirst + (num_links - num_robot_links) - 1;
    }
    why << ", got " << l;
    return why.str();
  }
  // The arm cover indexes links and spheres by what it carries
  // (ArmDistance).
  return check_arm_cover(labels);
}

// What the pixel classes leave for the later stages.
struct PixelClasses {
  PixelClasses(int height, int width)
      : mismatch_mask(height, width, uint8_t{0}),
        nearer_mask(height, width, uint8_t{0}),
        not_robot(height, width, uint8_t{255}) {}
  int count[6] = {0, 0, 0, 0, 0, 0};  // per discrepancy_t::PIXEL_*
  int num_compared = 0;               // camera and model both have a surface
  double sum_abs_dis_mm = 0;          // over the compared pixels
  // 255 where the camera sees farther than a modelled surface (for blobs),
  // and where it sees a nearer surface (occluded or unexpected, for the
  // protective fields); silhouette pixels left out of both except
  // unmodelled ones.
  cv::Mat1b mismatch_mask;
  cv::Mat1b nearer_mask;
  // 0 where the model has a robot link, 255 elsewhere (distance transform).
  cv::Mat1b not_robot;
  bool any_robot = false;
  // Per body region (link_labels_t.body_region order): the occupant's
  // modelled pixels with a camera depth, those the camera sees farther than
  // the envelope, and those it sees within it.
  std::vector<int32_t> region_modelled;
  std::vector<int32_t> region_missing;
  std::vector<int32_t> region_seen;
};

// A pixel where the model shows the occupant (shape `shape`) and the
// camera a surface, I_dis = `dis_mm`: within the tolerance and the region's
// envelope it is the user as modelled (a match); nearer, something is in
// front of the user (an unexplained nearer surface, judged in 3-D by
// unexplained_surfaces); farther, the user is not there: counted per
// region, not a mismatch blob (the risk judges an absent user).
int classify_occupant_pixel(int dis_mm, double tolerance_mm, int i, const OccupantShapes& occupant, int shape,
                            const std::vector<uint8_t>& silhouette, PixelClasses* p) {
  const int region = occupant.region_of_shape(shape);
  // Silhouette pixels mix the user with what is behind: not counted for
  // the region (their class is still the comparison's).
  const bool counted = silhouette[i] == 0;
  if (counted) p->region_modelled[region]++;
  ++p->num_compared;
  p->sum_abs_dis_mm += std::abs(dis_mm);
  if (std::abs(dis_mm) <= tolerance_mm + 1000.0 * occupant.envelope_m(region)) {
    if (counted) p->region_seen[region]++;
    return discrepancy_t::PIXEL_MATCH;
  }
  if (dis_mm > 0) {
    p->nearer_mask.ptr<uint8_t>()[i] = counted ? 255 : 0;
    return discrepancy_t::PIXEL_UNEXPECTED_SURFACE;
  }
  if (counted) p->region_missing[region]++;
  return discrepancy_t::PIXEL_ENVIRONMENT_MISSING;
}

// Stage 3, pixel classes: I_dis = I_gen - I_ToF (mm) and the class of every
// pixel (docs/safety-chain.md, "Pixel classes") into frame->pixel_class and
// frame->dis_mm (allocated by the caller), with the masks and totals the
// later stages need into `p` (fresh).
void classify_pixels(const depth_image_t& camera, const depth_image_t& rendered, const link_labels_t& labels,
                     const std::vector<uint8_t>& silhouette, const Tolerance& tolerance,
                     const OccupantShapes& occupant, DiscrepancyFrame* frame, PixelClasses* classes) {
  PixelClasses& p = *classes;
  const int num_shapes = occupant.num_shapes();
  p.region_modelled.assign(labels.num_body_regions, 0);
  p.region_missing.assign(labels.num_body_regions, 0);
  p.region_seen.assign(labels.num_body_regions, 0);
  const int num_links = labels.num_links;
  const int num_robot_links = labels.num_robot_links;
  const int16_t* label = labels.label.data();
  const int width = camera.width;
  const int height = camera.height;
  const int num_pixels = width * height;

  const int16_t* tof = camera.depth_mm.data();
  const int16_t* gen = rendered.depth_mm.data();
  uint8_t* pixel_class = frame->pixel_class.ptr<uint8_t>();
  int32_t* dis = frame->dis_mm.ptr<int32_t>();
  uint8_t* mismatch = p.mismatch_mask.ptr<uint8_t>();
  uint8_t* nearer = p.nearer_mask.ptr<uint8_t>();
  uint8_t* robot_free = p.not_robot.ptr<uint8_t>();
  for (int i = 0; i < num_pixels; ++i) {
    const int link = link_of_label(label[i], labels.num_robot_links, num_links);
    const int t = tof[i];
    const int g = gen[i];
    const bool modelled = g > 0;
    if (const int shape = occupant_shape_of_label(label[i], num_shapes); shape >= 0 && modelled && t > 0) {
      const int c = classify_occupant_pixel(g - t, tolerance.at(t), i, occupant, shape, silhouette, &p);
      dis[i] = g - t;
      pixel_class[i] = static_cast<uint8_t>(c);
      p.count[c]++;
      continue;
    }
    const bool robot = modelled && link >= 0 && link < num_robot_links;
    if (robot) {
      robot_free[i] = 0;
      p.any_robot = true;
    }
    dis[i] = 0;
    int8_t c;
    if (t <= 0) {
      c = discrepancy_t::PIXEL_INVALID;
    } else if (!modelled) {
      // The camera sees a surface where the model has none.
      c = discrepancy_t::PIXEL_UNEXPECTED_SURFACE;
      nearer[i] = 255;
    } else {
      const int d = g - t;
      dis[i] = d;
      const int magnitude = std::abs(d);
      p.sum_abs_dis_mm += magnitude;
      ++p.num_compared;
      if (magnitude <= tolerance.at(t)) {
        c = discrepancy_t::PIXEL_MATCH;
      } else if (d > 0) {
        c = robot ? discrepancy_t::PIXEL_OCCLUDED : discrepancy_t::PIXEL_UNEXPECTED_SURFACE;
        nearer[i] = silhouette[i] ? 0 : 255;
      } else {
        c = robot ? discrepancy_t::PIXEL_ROBOT_MISSING : discrepancy_t::PIXEL_ENVIRONMENT_MISSING;
        mismatch[i] = silhouette[i] ? 0 : 255;
      }
    }
    pixel_class[i] = static_cast<uint8_t>(c);
    p.count[c]++;
  }
}

// Stage 4, per-link statistics: per link the compared, matched, farther,
// nearer and invalid pixel counts (silhouettes left out of the compared
// ones) and the signed median of I_dis; the robust scores over the frame
// (median and 95th percentile of |I_dis|, signed medians of the robot's and
// the environment's pixels). Medians from 1 mm histograms.
//
// The histograms (32 kB each) are each thread's own and kept from frame to
// frame, cleared where they were used (Histogram): none is allocated or
// freed per frame. (Freed between stages, they let malloc hand the heap's
// top back to the kernel, and the later stages faulted it in again: 3x the
// frame time in tofguard-discrepancy-bench.)
struct DisHistograms {
  // Clears every histogram, with one per link plus one for modelled pixels
  // without a label.
  void reset(int num_links) {
    per_link.resize(static_cast<size_t>(num_links) + 1);
    for (Histogram& h : per_link) h.clear();
    for (Histogram* h : {&robot, &environment, &all, &abs}) h->clear();
  }
  std::vector<Histogram> per_link;
  Histogram robot;
  Histogram environment;
  Histogram all;
  Histogram abs;
};

void per_link_statistics(const DiscrepancyFrame& frame, const depth_image_t& camera,
                         const depth_image_t& rendered, const link_labels_t& labels,
                         const std::vector<uint8_t>& silhouette, discrepancy_t* s) {
  const int16_t* label = labels.label.data();
  const int num_links = s->num_links;
  const int num_robot_links = s->num_robot_links;
  const int num_pixels = camera.width * camera.height;
  const int16_t* tof = camera.depth_mm.data();
  const int16_t* gen = rendered.depth_mm.data();
  const uint8_t* pixel_class = frame.pixel_class.ptr<uint8_t>();
  const int32_t* dis = frame.dis_mm.ptr<int32_t>();
  thread_local DisHistograms h;
  h.reset(num_links);
  std::vector<Histogram>& link_dis = h.per_link;
  for (int i = 0; i < num_pixels; ++i) {
    // The occupant's pixels are judged by their envelopes, not by the
    // model's tolerance: no link's, and not in the frame's scores.
    if (label[i] >= kLabelOccupantFirst) continue;
    const int link = link_of_label(label[i], labels.num_robot_links, num_links);
    const bool modelled = gen[i] > 0;
    if (tof[i] <= 0) {
      if (link >= 0 && modelled) s->link_invalid[link]++;
      continue;
    }
    if (!modelled) continue;
    // Compared: both the camera and the model have a surface.
    const int d = dis[i];
    link_dis[link >= 0 ? link : num_links].add(d);
    if (link < 0 || silhouette[i]) continue;
    s->link_compared[link]++;
    if (pixel_class[i] == discrepancy_t::PIXEL_MATCH) {
      s->link_match[link]++;
    } else if (d > 0) {
      s->link_nearer[link]++;
    } else {
      s->link_farther[link]++;
    }
  }
  for (int link = 0; link < num_links; ++link) {
    s->link_median_dis_mm[link] = link_dis[link].median();
    (link < num_robot_links ? h.robot : h.environment).add(link_dis[link]);
  }
  h.all.add(h.robot);
  h.all.add(h.environment);
  h.all.add(link_dis[num_links]);
  h.all.add_folded_to(&h.abs);
  s->median_abs_dis_mm = h.abs.median();
  s->p95_abs_dis_mm = h.abs.quantile(0.95);
  s->robot_median_dis_mm = h.robot.median();
  s->environment_median_dis_mm = h.environment.median();
}

// Metric footprint of a pixel at the camera's depth (else the model's), m^2:
// (Z/fx)*(Z/fy).
class PixelFootprint {
 public:
  PixelFootprint(const depth_image_t& camera, const depth_image_t& rendered)
      : tof_(camera.depth_mm.data()),
        gen_(rendered.depth_mm.data()),
        inv_fx_fy_(1.0 / (camera.fx * camera.fy)) {}
  double m2(int i) const {
    const double z_m = metres_from_mm(tof_[i] > 0 ? tof_[i] : gen_[i]);
    return z_m * z_m * inv_fx_fy_;
  }

 private:
  const int16_t* tof_;
  const int16_t* gen_;
  double inv_fx_fy_;
};

// Stage 5, blobs: the largest 8-connected component of the opened mask of
// farther mismatches, its pixel count and metric area.
void largest_blob(const cv::Mat1b& mismatch_mask, int opening_radius_px, const PixelFootprint& footprint,
                  discrepancy_t* s) {
  const cv::Mat1b blobs = opened(mismatch_mask, opening_radius_px);
  cv::Mat1i component;
  cv::Mat stats;
  cv::Mat centroids;
  const int n = cv::connectedComponentsWithStats(blobs, component, stats, centroids, 8, CV_32S);
  int largest = 0;
  for (int k = 1; k < n; ++k) {
    if (largest == 0 || stats.at<int>(k, cv::CC_STAT_AREA) > stats.at<int>(largest, cv::CC_STAT_AREA)) {
      largest = k;
    }
  }
  if (largest == 0) return;
  s->largest_blob_pixels = stats.at<int>(largest, cv::CC_STAT_AREA);
  double area = 0;
  const int* comp = component.ptr<int>();
  const int num_pixels = static_cast<int>(component.total());
  for (int i = 0; i < num_pixels; ++i) {
    if (comp[i] == largest) area += footprint.m2(i);
  }
  s->largest_blob_area_m2 = static_cast<float>(area);
}

// The depth (mm) at which pixel i of `tof`, an unexplained nearer surface,
// stands for one. A mixed ("flying") pixel, whose return mixes two surfaces
// at a step, reads a depth between them where there is nothing. It is
// recognised by its neighbours: along some direction (horizontal, vertical
// or either diagonal) one is nearer and the opposite one farther, each by
// more than jump_mm. Its unexplained part is the neighbour that is itself
// an unexplained surface (`unexplained`): a cart's edge before the modelled
// wall is placed at the cart's depth (the nearer), a person passing behind
// the arm's edge at the person's (the farther), not on the arm. When both
// are, the nearer; when neither is (two explained surfaces mixed), and for
// any other pixel, its own depth.
int surface_depth_mm(const int16_t* tof, const uint8_t* unexplained, int i, int width, int height,
                     double jump_mm) {
  const int d = tof[i];
  const int u = i % width;
  const int v = i / width;
  int placed = std::numeric_limits<int>::max();
  constexpr int kAxes[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  for (const auto& axis : kAxes) {
    const int ua = u + axis[0], va = v + axis[1];
    const int ub = u - axis[0], vb = v - axis[1];
    if (ua < 0 || ub < 0 || ua >= width || ub >= width || va < 0 || vb < 0 || va >= height || vb >= height) {
      continue;
    }
    int nearer = va * width + ua;
    int farther = vb * width + ub;
    if (tof[nearer] <= 0 || tof[farther] <= 0) continue;
    if (tof[nearer] > tof[farther]) std::swap(nearer, farther);
    if (!(d - tof[nearer] > jump_mm && tof[farther] - d > jump_mm)) continue;
    if (unexplained[nearer] != 0) {
      placed = std::min(placed, static_cast<int>(tof[nearer]));
    } else if (unexplained[farther] != 0) {
      placed = std::min(placed, static_cast<int>(tof[farther]));
    }
  }
  return placed == std::numeric_limits<int>::max() ? d : placed;
}

// The user's seen surfaces per body region: the pixel classes' counts,
// the unexplained surfaces found within an envelope, and each region's
// smallest seen distance to the arm's cover (-1: none seen, or no cover).
class UserSightings {
 public:
  explicit UserSightings(const PixelClasses& classes)
      : modelled_(classes.region_modelled),
        missing_(classes.region_missing),
        seen_(classes.region_seen),
        separation_m_(classes.region_seen.size(), -1.0f) {}
  void saw(int region, double distance_to_arm_m) {
    seen_[region]++;
    if (distance_to_arm_m < 0) return;
    float& best = separation_m_[region];
    // Rounded down to a float: never more than the distance computed.
    float d = static_cast<float>(distance_to_arm_m);
    if (d > distance_to_arm_m) d = std::nextafter(d, 0.0f);
    if (best < 0 || d < best) best = d;
  }
  void write(discrepancy_t* s) const {
    s->body_region_modelled_pixels = modelled_;
    s->body_region_missing_pixels = missing_;
    s->body_region_seen_pixels = seen_;
    s->body_region_seen_separation_m = separation_m_;
  }

 private:
  std::vector<int32_t> modelled_;
  std::vector<int32_t> missing_;
  std::vector<int32_t> seen_;
  std::vector<float> separation_m_;
};

// The volume behind the occluded pixels (hidden_distance_m), examined on
// every second pixel in u and v: the pixel at even u and v of each 2 x 2
// block stands for the block's others where it is occluded itself. Their
// rays lie within 2 pixels of its own (at most 2 Z / fx apart: 18 mm at
// 2 m before the default camera), under the detection capability of
// 39 mm, so an object of that size behind one lies on the other's ray too;
// a quarter of the rays to walk.
class HiddenVolumeGrid {
 public:
  HiddenVolumeGrid(int width, int height)
      : width_(width),
        hidden_m_(static_cast<size_t>(width) * height, std::numeric_limits<double>::quiet_NaN()) {}

  // Pixel i's hidden distance: its block's anchor's where that one has
  // one, else `compute()`'s (kept when pixel i is the anchor).
  template <typename Compute>
  double at(int i, const Compute& compute) {
    const int u = i % width_;
    const int v = i / width_;
    const auto anchor = static_cast<size_t>((v & ~1) * width_ + (u & ~1));
    if (!std::isnan(hidden_m_[anchor])) return hidden_m_[anchor];
    const double h = compute();
    if (anchor == static_cast<size_t>(i)) hidden_m_[anchor] = h;
    return h;
  }

 private:
  int width_;
  std::vector<double> hidden_m_;
};

// Stage 6's look through other cameras' frames (witness_views.hpp): the
// rendered frame gives each occluded pixel's arm point.
struct LookThrough {
  const depth_image_t& rendered;
  const std::vector<WitnessView>& witnesses;
};

// Stage 6, unexplained nearer surfaces and the protective fields: every
// occluded or unexpected-surface pixel (after the opening, on surfaces:
// opened_on_surfaces)
// back-projected at the camera's depth (a mixed pixel at its unexplained
// neighbour's, surface_depth_mm), and its distance to the arm: 0 for
// an occluded pixel (it hides part of the arm, and what cannot be seen is
// occupied; with other cameras' frames, `look`, the distance of what may
// lie behind it: hidden_distance_m), else the distance to the arm's cover (arm_distance.hpp; 0 for
// every pixel when the labels carry no cover). Fills
// near_arm_* (within near_arm_m) and the cumulative areas by distance
// (field_*).
void unexplained_surfaces(const depth_image_t& camera, const link_labels_t& labels,
                          const DiscrepancyFrame& frame, const PixelClasses& classes,
                          const OccupantShapes& occupant, const DiscrepancyOptions& options,
                          const PixelFootprint& footprint, const LookThrough& look, discrepancy_t* s) {
  UserSightings user(classes);
  s->near_arm_min_distance_m = -1;
  s->field_available = labels.num_arm_spheres > 0;
  const int num_bins = static_cast<int>(std::ceil(options.field_range_m / options.field_bin_m - 1e-9));
  s->field_bin_m = static_cast<float>(options.field_bin_m);
  s->num_field_bins = num_bins;
  std::vector<double> area_in_bin(num_bins, 0.0);
  const cv::Mat1b candidates = opened_on_surfaces(classes.nearer_mask, camera.depth_mm.data(),
                                                  options.opening_radius_px, options.silhouette_jump_mm);
  const ArmDistance arm(labels);
  const int width = camera.width;
  const int num_pixels = width * camera.height;
  const int16_t* tof = camera.depth_mm.data();
  const uint8_t* pixel_class = frame.pixel_class.ptr<uint8_t>();
  const uint8_t* candidate = candidates.ptr<uint8_t>();
  const double up_to_m = std::max(options.field_range_m, options.near_arm_m);
  double min_distance = std::numeric_limits<double>::infinity();
  double near_area = 0;
  s->witness_frames = static_cast<int32_t>(look.witnesses.size());
  const bool looking_through = s->field_available && !look.witnesses.empty() && labels.optical_pose_given;
  const Eigen::Isometry3d world_from_camera =
      looking_through ? world_from_optical(labels) : Eigen::Isometry3d::Identity();
  HiddenVolumeGrid hidden(width, camera.height);
  for (int i = 0; i < num_pixels; ++i) {
    if (candidate[i] == 0) continue;
    const bool occluded = pixel_class[i] == discrepancy_t::PIXEL_OCCLUDED;
    const bool measured = s->field_available && (!occluded || looking_through);
    // The camera-frame point of pixel i at its depth, once, where needed.
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    if (measured || !occupant.empty()) {
      point = optical_point_m(camera, i,
                              metres_from_mm(surface_depth_mm(tof, candidate, i, width, camera.height,
                                                              options.silhouette_jump_mm)));
    }
    if (!occupant.empty()) {
      // A surface within a region's envelope is the user (hiding the arm
      // or not): not an unknown object, but how near the user's seen body
      // is to the arm.
      if (const int region = occupant.region_holding(point); region >= 0) {
        // Beyond up_to_m the search gives some value >= it: up_to_m, never
        // more than the truth.
        user.saw(region, s->field_available ? std::min(arm.distance_m(point, up_to_m), up_to_m) : -1.0);
        continue;
      }
    }
    double distance_m = measured ? arm.distance_m(point, up_to_m) : 0.0;
    if (occluded && looking_through) {
      // What may lie between the surface and the arm behind it.
      const Eigen::Vector3d arm_point = optical_point_m(camera, i, metres_from_mm(look.rendered.depth_mm[i]));
      // (Points of the volume no nearer than the surface itself cannot
      // change the pixel's distance: searched up to it.)
      const double surface_m = distance_m;
      distance_m = std::min(distance_m, hidden.at(i, [&] {
        return hidden_distance_m(point, arm_point, world_from_camera, look.witnesses, arm, options.tolerance,
                                 options.hidden_volume, std::min(up_to_m, surface_m));
      }));
      if (distance_m > 0) s->occluded_seen_by_witnesses++;
    }
    const double area = footprint.m2(i);
    if (distance_m <= options.near_arm_m) {
      s->near_arm_pixels++;
      near_area += area;
      min_distance = std::min(min_distance, distance_m);
    }
    // Bin k holds (k*bin, (k+1)*bin]; distance 0 goes to bin 0.
    const int bin = std::max(0, static_cast<int>(std::ceil(distance_m / options.field_bin_m)) - 1);
    if (bin < num_bins) area_in_bin[bin] += area;
  }
  s->near_arm_area_m2 = static_cast<float>(near_area);
  if (s->near_arm_pixels > 0) s->near_arm_min_distance_m = static_cast<float>(min_distance);
  user.write(s);
  s->unexplained_area_within_m2.resize(num_bins);
  double cumulative = 0;
  for (int k = 0; k < num_bins; ++k) {
    cumulative += area_in_bin[k];
    s->unexplained_area_within_m2[k] = static_cast<float>(cumulative);
  }
}

// Stage 2b, the arm hidden: `camera` with no return wherever a robot
// link's pixel shows a nearer surface (beyond the tolerance) that says
// nothing about the link behind it:
// - one within a body region's envelope of the user: the user's own hand
//   before a link (`*by_user`);
// - with other cameras looking through (`far_objects`), one farther than
//   options.near_arm_m from the arm's cover, where no moved link shows
//   (`*by_objects`). With one camera such a surface stops the arm anyway.
// The per-link counts and the evidence take such a pixel as they take one
// without a return; the pixel classes and the unexplained surfaces still
// see it. nullopt when no pixel is hidden so.
std::optional<depth_image_t> arm_hidden(const depth_image_t& camera, const depth_image_t& rendered,
                                        const link_labels_t& labels, const OccupantShapes& occupant,
                                        const DiscrepancyOptions& options, bool far_objects, int32_t* by_user,
                                        int32_t* by_objects) {
  *by_user = 0;
  *by_objects = 0;
  far_objects = far_objects && labels.num_arm_spheres > 0;
  if (occupant.empty() && !far_objects) return std::nullopt;
  // (The cover is searched only for far objects: not built otherwise.)
  const std::optional<ArmDistance> arm = far_objects ? std::optional<ArmDistance>(labels) : std::nullopt;
  std::optional<depth_image_t> out;
  const int width = camera.width;
  const int num_pixels = width * camera.height;
  for (int i = 0; i < num_pixels; ++i) {
    const int t = camera.depth_mm[i];
    const int g = rendered.depth_mm[i];
    const int link = link_of_label(labels.label[i], labels.num_robot_links, labels.num_links);
    if (t <= 0 || g <= 0 || link < 0 || link >= labels.num_robot_links || g - t <= options.tolerance.at(t))
      continue;
    const Eigen::Vector3d point = optical_point_m(camera, i, metres_from_mm(t));
    if (!occupant.empty() && occupant.region_holding(point) >= 0) {
      ++*by_user;
    } else if (arm && arm->distance_m(point, 2 * options.near_arm_m) > options.near_arm_m) {
      ++*by_objects;
    } else {
      continue;
    }
    if (!out) out = camera;
    out->depth_mm[i] = 0;
  }
  return out;
}

// The frame's identity and size, nothing judged: not usable, no
// invalid pixels counted (unusable_summary counts them; a usable frame's
// pixel stages do).
discrepancy_t summary_of_frame(const depth_image_t& camera) {
  discrepancy_t s{};
  s.utime = camera.utime;
  s.seq = camera.seq;
  s.camera_id = camera.camera_id;
  s.usable = false;
  s.unusable_kind = discrepancy_t::UNUSABLE_NONE;
  s.calibrated = camera.calibrated;
  s.width = camera.width;
  s.height = camera.height;
  s.num_pixels = camera.num_pixels;
  s.near_arm_min_distance_m = -1;
  s.camera_search_axis = -1;
  return s;
}

// The arm's reach about each joint (arm_distance.hpp), num_joints entries
// (num_joints is 0 without kinematics; all 0 without a cover), from
// `reach` = joint_reach_m(labels) (empty when the frame has no protective
// field), once the evidence has set num_joints.
void joint_reach(const std::vector<double>& reach, discrepancy_t* s) {
  s->joint_reach_m.assign(s->num_joints, 0.0);
  if (!s->field_available) return;
  if (reach.size() == static_cast<size_t>(s->num_joints)) s->joint_reach_m = reach;
}

// The labels' body regions and their separations from the arm, as they
// came (checked with the labels, check_link_labels).
void body_regions(const link_labels_t& labels, discrepancy_t* s) {
  s->num_body_regions = labels.num_body_regions;
  s->body_region = labels.body_region;
  s->body_region_separation_m = labels.body_region_separation_m;
}

}  // namespace

// Stage 2 (the header says why).
std::vector<uint8_t> silhouette_mask(const depth_image_t& rendered, double silhouette_jump_mm) {
  const int width = rendered.width;
  const int height = rendered.height;
  const int16_t* gen = rendered.depth_mm.data();
  std::vector<uint8_t> silhouette(static_cast<size_t>(width) * height, 0);
  if (!(silhouette_jump_mm > 0)) return silhouette;
  // silhouette_step in whole millimetres; a pixel with depth beside one
  // without is a silhouette too.
  const int limit = silhouette_step_limit_mm(silhouette_jump_mm);
  const auto step = [limit](int a, int b) {
    return (a > 0) != (b > 0) || (a > 0 && std::abs(a - b) > limit);
  };
  uint8_t* mask = silhouette.data();
  for (int v = 0; v < height; ++v) {
    const int row = v * width;
    for (int u = 0; u + 1 < width; ++u) {
      if (step(gen[row + u], gen[row + u + 1])) mask[row + u] = mask[row + u + 1] = 1;
    }
  }
  for (int v = 0; v + 1 < height; ++v) {
    const int row = v * width;
    for (int u = 0; u < width; ++u) {
      if (step(gen[row + u], gen[row + width + u])) mask[row + u] = mask[row + width + u] = 1;
    }
  }
  return silhouette;
}

DiscrepancyOptions discrepancy_options(const DiscrepancySettings& config) {
  DiscrepancyOptions p;
  p.tolerance.noise.sigma_at_0m_mm = config.noise_sigma_at_0m_mm;
  p.tolerance.noise.sigma_per_m2_mm = config.noise_sigma_per_m2_mm;
  p.tolerance.sigmas = config.tolerance_sigmas;
  p.tolerance.model_mm = config.model_tolerance_mm;
  p.opening_radius_px = config.opening_radius_px;
  p.silhouette_jump_mm = config.silhouette_jump_mm;
  p.near_arm_m = config.near_arm_m;
  p.field_range_m = config.field_range_m;
  p.field_bin_m = config.field_bin_m;
  p.max_depth_mm = config.max_depth_mm;
  p.evidence.model_sigma_mm = config.evidence_model_sigma_mm;
  p.evidence.clip_sigmas = config.evidence_clip_sigmas;
  p.evidence.naming_gate_sigmas = config.evidence_naming_gate_sigmas;
  p.evidence.pixels_per_sample = config.evidence_pixels_per_sample;
  p.evidence.max_pixels = config.evidence_max_pixels;
  p.evidence.search_range_rad = config.evidence_search_range_rad;
  p.evidence.search_step_rad = config.evidence_search_step_rad;
  p.evidence.search_range_m = config.evidence_search_range_m;
  p.evidence.search_step_m = config.evidence_search_step_m;
  p.evidence.search_max_points = config.evidence_search_max_points;
  p.evidence.static_bias_mm = config.evidence_static_bias_mm;
  if (config.camera_profile) p.camera_profile = config.camera_profile;
  p.evidence.fixed_pattern_sigma_mm = config.evidence_fixed_pattern_sigma_mm;
  p.evidence.silhouette_band_px = config.evidence_silhouette_band_px;
  p.evidence.silhouette_bias_mm = config.evidence_silhouette_bias_mm;
  p.evidence.silhouette_bias_by_link_mm = config.evidence_silhouette_bias_by_link_mm;
  p.evidence.silhouette_band_step_mm = config.evidence_silhouette_band_step_mm;
  return p;
}

discrepancy_t unusable_summary(const depth_image_t& camera, int8_t kind, const std::string& reason) {
  discrepancy_t s = summary_of_frame(camera);
  s.unusable_kind = kind;
  s.unusable_reason = reason;
  for (int16_t d : camera.depth_mm) s.num_invalid += d <= 0 ? 1 : 0;
  s.invalid_fraction = s.num_pixels > 0 ? static_cast<float>(s.num_invalid) / s.num_pixels : 1.0f;
  return s;
}

namespace {

// compute_discrepancy on the frame as it is (after the camera profile).
DiscrepancyFrame compare_frames(const depth_image_t& camera, const depth_image_t& rendered,
                                const link_labels_t& labels, const DiscrepancyOptions& options,
                                WorkerPool* workers, const std::vector<WitnessView>& witnesses) {
  // The workers' first call comes after the checks and the silhouettes:
  // woken now, they are awake by then (WorkerPool: a wake-up through the
  // hypervisor is slow).
  if (workers != nullptr) workers->expect_call_within(kWorkersExpected);
  DiscrepancyFrame frame;
  if (!labels.usable) {
    frame.summary =
        unusable_summary(camera, discrepancy_t::UNUSABLE_RENDERER, "renderer: " + labels.unusable_reason);
    return frame;
  }
  if (const std::string why = mismatch_reason(camera, rendered, labels); !why.empty()) {
    frame.summary = unusable_summary(camera, discrepancy_t::UNUSABLE_MISMATCHED, why);
    return frame;
  }
  // Every stage below reads the three images through raw pointers up to
  // width * height pixels. The wire checks (num_pixels == width * height,
  // decoded arrays of num_pixels) and mismatch_reason (same sizes) guarantee
  // it; a caller that skipped them would read past the end.
  const int num_pixels = camera.width * camera.height;
  TOFGUARD_DEMAND(camera.depth_mm.size() == static_cast<size_t>(num_pixels) &&
                      rendered.depth_mm.size() == static_cast<size_t>(num_pixels) &&
                      labels.label.size() == static_cast<size_t>(num_pixels),
                  "frame seq " + std::to_string(camera.seq) +
                      ": image arrays do not hold width*height = " + std::to_string(num_pixels) + " pixels");
  if (const std::string why = check_labels(labels); !why.empty()) {
    frame.summary = unusable_summary(camera, discrepancy_t::UNUSABLE_MISMATCHED, why);
    return frame;
  }

  const int num_links = labels.num_links;
  discrepancy_t& s = frame.summary;
  // (num_invalid and invalid_fraction: the pixel stages', from the classes.)
  s = summary_of_frame(camera);
  s.usable = true;
  s.num_robot_links = labels.num_robot_links;
  s.num_links = num_links;
  s.link_name = labels.link_name;
  s.link_compared.assign(num_links, 0);
  s.link_match.assign(num_links, 0);
  s.link_farther.assign(num_links, 0);
  s.link_nearer.assign(num_links, 0);
  s.link_invalid.assign(num_links, 0);
  s.link_median_dis_mm.assign(num_links, 0.0f);

  const std::vector<uint8_t> silhouette = silhouette_mask(rendered, options.silhouette_jump_mm);
  const OccupantShapes occupant(labels);
  const std::optional<depth_image_t> unhidden =
      arm_hidden(camera, rendered, labels, occupant, options, options.other_cameras || !witnesses.empty(),
                 &s.num_robot_hidden_by_user, &s.num_robot_hidden_by_objects);
  const depth_image_t& camera_for_arm = unhidden ? *unhidden : camera;
  std::vector<double> reach;  // the pixel stages' (joint_reach)
  // Stages 3 to 6 need nothing from the evidence, nor it from them (they
  // write other fields of the summary; the joints' reach, too, is the
  // labels' only): they run as one more task beside
  // the naming search's trials (SideTask), so that a thread the trials
  // leave free does them.
  SideTask pixel_stages([&] {
    frame.pixel_class.create(camera.height, camera.width);
    frame.dis_mm.create(camera.height, camera.width);
    PixelClasses classes(camera.height, camera.width);
    classify_pixels(camera, rendered, labels, silhouette, options.tolerance, occupant, &frame, &classes);

    // The seed's score and the class counts.
    s.num_match = classes.count[discrepancy_t::PIXEL_MATCH];
    s.num_robot_missing = classes.count[discrepancy_t::PIXEL_ROBOT_MISSING];
    s.num_occluded = classes.count[discrepancy_t::PIXEL_OCCLUDED];
    s.num_unexpected_surface = classes.count[discrepancy_t::PIXEL_UNEXPECTED_SURFACE];
    s.num_environment_missing = classes.count[discrepancy_t::PIXEL_ENVIRONMENT_MISSING];
    s.num_invalid = classes.count[discrepancy_t::PIXEL_INVALID];
    s.invalid_fraction = static_cast<float>(s.num_invalid) / static_cast<float>(num_pixels);
    s.num_compared = classes.num_compared;
    s.sum_abs_dis_mm = classes.sum_abs_dis_mm;
    s.normalized_sum_abs_dis =
        s.num_compared > 0 ? classes.sum_abs_dis_mm / (s.num_compared * options.max_depth_mm) : 0.0;
    s.mismatch_fraction =
        s.num_compared > 0 ? static_cast<float>(s.num_compared - s.num_match) / s.num_compared : 0.0f;

    per_link_statistics(frame, camera_for_arm, rendered, labels, silhouette, &s);
    const PixelFootprint footprint(camera, rendered);
    largest_blob(classes.mismatch_mask, options.opening_radius_px, footprint, &s);
    unexplained_surfaces(camera, labels, frame, classes, occupant, options, footprint, {rendered, witnesses},
                         &s);
    if (s.field_available) reach = joint_reach_m(labels);
    if (!witnesses.empty() && labels.optical_pose_given) {
      const Registration r = registration(camera, labels, frame.pixel_class.ptr<uint8_t>(),
                                          world_from_optical(labels), witnesses, options.tolerance);
      s.registration_points = r.points;
      s.registration_median_mm = static_cast<float>(r.median_mm);
      s.registration_mismatch_fraction = static_cast<float>(r.mismatch_fraction);
    }
  });
  // Stage 7, evidence (evidence.hpp).
  compute_evidence(camera_for_arm, rendered, labels, silhouette, options.silhouette_jump_mm,
                   options.tolerance.noise, options.evidence, &s, workers, &pixel_stages);
  pixel_stages.run_once();
  joint_reach(reach, &s);
  body_regions(labels, &s);
  return frame;
}

}  // namespace

namespace {

// Why the arm of `rendered` is where `profile` was not measured
// (ProfileCoverage beyond kMaxShareOutsideProfile), one line; empty when it
// is not, or when the labels cannot say (compare_frames refuses them).
std::string outside_profile(const CameraProfile& profile, const depth_image_t& rendered,
                            const link_labels_t& labels) {
  if (!labels.usable) return "";
  ProfileCoverage c;
  add_profile_coverage(profile, rendered, labels, {}, &c);
  if (c.outside_share() <= kMaxShareOutsideProfile) return "";
  std::ostringstream why;
  why << std::fixed << std::setprecision(2) << "camera needs recommissioning: the arm is " << c.nearest_m
      << "-" << c.farthest_m << " m from it (radial, the model's), beyond the " << c.first_m << "-"
      << c.last_m << " m its profile " << (profile.file.empty() ? std::string("(in memory)") : profile.file)
      << " was measured over (" << std::setprecision(1) << 100 * c.outside_share()
      << " % of the arm's pixels; at most " << 100 * kMaxShareOutsideProfile
      << " %): commission it on a recording through the arm's whole workspace";
  return why.str();
}

}  // namespace

DiscrepancyFrame compute_discrepancy(const depth_image_t& camera, const depth_image_t& rendered,
                                     const link_labels_t& labels, const DiscrepancyOptions& options,
                                     WorkerPool* workers, const std::vector<WitnessView>& witnesses) {
  if (!options.camera_profile) return compare_frames(camera, rendered, labels, options, workers, witnesses);
  // The camera's commissioned profile, checked against the frame (a frame
  // of another camera, size or intrinsics would be corrected wrongly).
  if (const std::string why = profile_mismatch(*options.camera_profile, camera); !why.empty()) {
    DiscrepancyFrame frame;
    frame.summary = unusable_summary(camera, discrepancy_t::UNUSABLE_MISMATCHED, why);
    return frame;
  }
  if (const std::string why = outside_profile(*options.camera_profile, rendered, labels); !why.empty()) {
    DiscrepancyFrame frame;
    frame.summary = unusable_summary(camera, discrepancy_t::UNUSABLE_OUTSIDE_PROFILE, why);
    return frame;
  }
  depth_image_t corrected = camera;
  apply_camera_profile(*options.camera_profile, &corrected, &labels);
  return compare_frames(corrected, rendered, labels, options, workers, witnesses);
}

Eigen::Vector3d optical_point_m(const depth_image_t& camera, int i, double z_m) {
  return tofguard::optical_point_m(camera, i % camera.width, i / camera.width, z_m);
}

int64_t depth_hash(const std::vector<int16_t>& depth_mm) {
  uint64_t hash = 0xcbf29ce484222325ULL;
  for (int16_t d : depth_mm) {
    const auto bits = static_cast<uint16_t>(d);
    hash = (hash ^ (bits & 0xffu)) * 0x100000001b3ULL;
    hash = (hash ^ (bits >> 8)) * 0x100000001b3ULL;
  }
  return static_cast<int64_t>(hash);
}

int32_t RepeatCounter::update(int64_t hash) {
  repeats_ = (has_previous_ && hash == previous_) ? repeats_ + 1 : 0;
  has_previous_ = true;
  previous_ = hash;
  return repeats_;
}

discrepancy_image_t colour_image(const DiscrepancyFrame& frame, double full_scale_mm) {
  discrepancy_image_t image;
  image.utime = frame.summary.utime;
  image.seq = frame.summary.seq;
  image.camera_id = frame.summary.camera_id;
  image.width = frame.summary.width;
  image.height = frame.summary.height;
  const int num_pixels = image.width * image.height;
  image.num_bytes = 3 * num_pixels;
  image.rgb.assign(image.num_bytes, 0);
  if (frame.pixel_class.empty()) return image;
  // The class and I_dis images were made with the summary's size.
  TOFGUARD_DEMAND(frame.pixel_class.total() == static_cast<size_t>(num_pixels) &&
                      frame.dis_mm.total() == static_cast<size_t>(num_pixels),
                  "discrepancy images do not match the summary's " + std::to_string(image.width) + "x" +
                      std::to_string(image.height));
  const uint8_t* pixel_class = frame.pixel_class.ptr<uint8_t>();
  const int32_t* dis = frame.dis_mm.ptr<int32_t>();
  for (int i = 0; i < num_pixels; ++i) {
    const uint8_t c = pixel_class[i];
    if (c == discrepancy_t::PIXEL_MATCH || c == discrepancy_t::PIXEL_INVALID || dis[i] == 0) continue;
    const double level = std::min(255.0, 255.0 * std::abs(dis[i]) / full_scale_mm);
    const auto value = static_cast<uint8_t>(std::max(1.0, level));
    // Red (channel 0) where the camera sees nearer, blue (2) farther.
    image.rgb[3 * i + (dis[i] > 0 ? 0 : 2)] = value;
  }
  return image;
}

}  // namespace tofguard::discrepancy
