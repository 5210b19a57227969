#include "tofguard/discrepancy/joint_search.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>
#include <limits>
#include <vector>

#include <Eigen/Geometry>

#include "double2.hpp"
#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/common/depth_frame.hpp"

namespace tofguard::discrepancy {
namespace {

// The coarse trials' points per joint, at most (see search_joint_offsets).
constexpr size_t kCoarsePoints = 1500;

// How often (in pairs of points) PointCost::link_cost compares a trial's
// partial cost with its bound: often enough to leave a hopeless trial after
// a few percent of its points, rarely enough that the test costs nothing.
constexpr int kBoundCheckPairs = 8;
// The interleaved passes over a link's points (PointCost::link_cost).
constexpr size_t kVisitPasses = 16;
// A trial is left only when its partial cost, summed in another order than
// the finished cost is, exceeds the bound by this fraction. Both sums add
// n >= 0 terms, so each is within (n - 1) * 2^-53 (relative) of the exact
// sum (Higham, "Accuracy and Stability of Numerical Algorithms", 4.2): for
// fewer than 10^6 points a partial sum 1e-6 above the bound means the
// finished cost is above it too, whatever the order.
constexpr double kPruneMargin = 1e-6;

// A rendered robot point: optical frame, mm, and 1 / sigma_i (1/mm).
struct SearchPoint {
  Eigen::Vector3d p_mm;
  double inv_sigma;
};

// A rigid motion (optical frame, mm) as 12 plain numbers, applied inline:
// Eigen's Isometry3d * Vector3d is a call per point in the search's inner
// loop. The sums run in Eigen's order ((r0 p0 + r1 p1) + r2 p2) + t, so the
// moved points are the same to the last bit (the bench's digest,
// docs/benchmarks.md, "The hot paths").
struct RigidMotion {
  explicit RigidMotion(const Eigen::Isometry3d& m) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) rotation[3 * r + c] = m.linear()(r, c);
      translation[r] = m.translation()[r];
    }
  }
  double x(const Eigen::Vector3d& p) const { return apply(0, p); }
  double y(const Eigen::Vector3d& p) const { return apply(1, p); }
  double z(const Eigen::Vector3d& p) const { return apply(2, p); }
  double apply(int r, const Eigen::Vector3d& p) const {
    const double* row = rotation + 3 * r;
    return ((row[0] * p.x() + row[1] * p.y()) + row[2] * p.z()) + translation[r];
  }
  // Row r of two points at once (x, y, z: their coordinates side by
  // side), each lane as apply().
  Double2 apply(int r, Double2 x, Double2 y, Double2 z) const {
    const double* row = rotation + 3 * r;
    return ((row[0] * x + row[1] * y) + row[2] * z) + translation[r];
  }
  double rotation[9];
  double translation[3];
};

// What the points of some links cost against the measured depth when moved
// by one rigid motion.
class PointCost {
 public:
  PointCost(const depth_image_t& camera, const depth_image_t& rendered, double clip_sigmas, double weight)
      : width_(camera.width),
        height_(camera.height),
        width_d_(camera.width),
        height_d_(camera.height),
        fx_(rendered.fx),
        fy_(rendered.fy),
        cx_(rendered.cx),
        cy_(rendered.cy),
        clip2_(clip_sigmas * clip_sigmas),
        weight_(weight),
        tof_(camera.depth_mm.data()) {}

  // Marks in `mask` (1) the pixels, `block` x `block` around where each
  // moved point lands, where the point matches the measured depth (within
  // clip_sigmas) and `is_static`(pixel) holds.
  template <typename IsStatic>
  void mark_matches(const std::vector<SearchPoint>& points, const Eigen::Isometry3d& motion, int block,
                    const IsStatic& is_static, std::vector<uint8_t>* mask) const {
    const double clip = std::sqrt(clip2_);
    const RigidMotion m(motion);
    for (const SearchPoint& point : points) {
      const double qz = m.z(point.p_mm);
      int u = 0;
      int v = 0;
      if (!lands(m.x(point.p_mm), m.y(point.p_mm), qz, &u, &v)) continue;
      const int measured = tof_[v * width_ + u];
      if (measured <= 0 || std::abs(qz - measured) * point.inv_sigma > clip) continue;
      const int u0 = std::max(0, u - block / 2);
      const int v0 = std::max(0, v - block / 2);
      for (int y = v0; y < std::min(height_, v0 + block); ++y) {
        for (int x = u0; x < std::min(width_, u0 + block); ++x) {
          const int i = y * width_ + x;
          if (is_static(i)) (*mask)[i] = 1;
        }
      }
    }
  }

  // The cost of one link's points moved by `motion`: every `every`-th point
  // (the coarse trials), each standing for `every`, into *cost; or false,
  // without a cost, as soon as `others` + the cost of the points seen so
  // far is above `prune_above` (checked every kBoundCheckPairs pairs).
  //
  // The points are visited in kVisitPasses interleaved passes (every
  // kVisitPasses-th of the chosen points, then the ones after them, ...),
  // so that the first ones seen lie all over the link and a hopeless trial
  // is left after a few of them. Each point's cost is kept in `point_cost`
  // (scratch) and the finished sum taken in the points' order, as one pass
  // in order would: the same to the last bit. Two points at a time
  // (Double2: the moved points and where they land the same to the last
  // bit as one at a time).
  bool link_cost(const std::vector<SearchPoint>& points, const Eigen::Isometry3d& motion, size_t every,
                 double others, double prune_above, std::vector<double>* point_cost, double* cost) const {
    const double scale = weight_ * static_cast<double>(every);
    const size_t chosen = (points.size() + every - 1) / every;
    point_cost->resize(chosen);
    double* pc = point_cost->data();
    const RigidMotion m(motion);
    const auto cost_of = [&](double qz, bool landed, double uf, double vf, double inv_sigma) {
      const int measured = landed ? tof_[static_cast<int>(vf) * width_ + static_cast<int>(uf)] : 0;
      if (measured <= 0) return clip2_;
      const double x = (qz - measured) * inv_sigma;
      return std::min(x * x, clip2_);
    };
    const Double2 one_mm = {1.0, 1.0};
    const Double2 zero = {0.0, 0.0};
    const Double2 width = {width_d_, width_d_};
    const Double2 height = {height_d_, height_d_};
    const size_t passes = std::min<size_t>(kVisitPasses, chosen);
    double seen = 0;  // the points visited so far, in the order visited
    int pairs = 0;
    for (size_t pass = 0; pass < passes; ++pass) {
      size_t q = pass;
      for (; q + passes < chosen; q += 2 * passes) {
        if (++pairs == kBoundCheckPairs) {
          pairs = 0;
          if (others + scale * seen > prune_above) return false;
        }
        const SearchPoint& a = points[q * every];
        const SearchPoint& b = points[(q + passes) * every];
        const Double2 px = {a.p_mm.x(), b.p_mm.x()};
        const Double2 py = {a.p_mm.y(), b.p_mm.y()};
        const Double2 pz = {a.p_mm.z(), b.p_mm.z()};
        const Double2 qz = m.apply(2, px, py, pz);
        // lands(), both lanes (a lane behind the camera computes nonsense
        // that the test below discards).
        const Double2 inv_z = 1.0 / qz;
        const Double2 uf = fx_ * m.apply(0, px, py, pz) * inv_z + cx_ + 0.5;
        const Double2 vf = fy_ * m.apply(1, px, py, pz) * inv_z + cy_ + 0.5;
        // in_image(), both lanes: all ones where it holds.
        const auto landed = (qz > one_mm) & (uf >= zero) & (vf >= zero) & (uf < width) & (vf < height);
        pc[q] = cost_of(qz[0], landed[0] != 0, uf[0], vf[0], a.inv_sigma);
        pc[q + passes] = cost_of(qz[1], landed[1] != 0, uf[1], vf[1], b.inv_sigma);
        seen += pc[q] + pc[q + passes];
      }
      if (q < chosen) {
        const SearchPoint& a = points[q * every];
        const double qz = m.z(a.p_mm);
        int u = 0;
        int v = 0;
        const bool landed = lands(m.x(a.p_mm), m.y(a.p_mm), qz, &u, &v);
        pc[q] = cost_of(qz, landed, u, v, a.inv_sigma);
        seen += pc[q];
      }
    }
    double sum = 0;
    for (size_t q = 0; q < chosen; ++q) sum += pc[q];
    *cost = scale * sum;
    return true;
  }

 private:
  // The pixel (u, v) nearest to where point (qx, qy, qz) (optical frame,
  // mm) projects; false when it is behind the camera or off the image.
  // Rounds by +0.5 and truncation (both >= 0 once in range).
  bool lands(double qx, double qy, double qz, int* u, int* v) const {
    if (!(qz > 1.0)) return false;
    const double inv_z = 1.0 / qz;
    const double uf = fx_ * qx * inv_z + cx_ + 0.5;
    const double vf = fy_ * qy * inv_z + cy_ + 0.5;
    if (!in_image(qz, uf, vf)) return false;
    *u = static_cast<int>(uf);
    *v = static_cast<int>(vf);
    return true;
  }
  // Whether a point at depth qz (mm) whose pixel coordinates are uf, vf
  // (+0.5, to truncate) is in front of the camera and on the image.
  bool in_image(double qz, double uf, double vf) const {
    return qz > 1.0 && uf >= 0 && vf >= 0 && uf < width_d_ && vf < height_d_;
  }

  int width_;
  int height_;
  double width_d_, height_d_;  // the same as doubles
  double fx_, fy_, cx_, cy_;
  double clip2_;
  double weight_;
  const int16_t* tof_;
};

// The rigid motion of one axis moved by `amount` (rad, or mm for a
// prismatic axis) about / along its line as rendered.
Eigen::Isometry3d axis_motion(const LabelAxis& axis, double amount) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  if (axis.prismatic) {
    t.translation() = amount * axis.direction;
  } else {
    t.linear() = Eigen::AngleAxisd(amount, axis.direction).toRotationMatrix();
    t.translation() = axis.origin_mm - t.linear() * axis.origin_mm;
  }
  return t;
}

// The robot link (one a joint moves) that pixel i of the rendered image
// shows; -1 for none (no rendered depth, a static label, or a link without
// an axis).
class MovedLinkOf {
 public:
  MovedLinkOf(const depth_image_t& rendered, const link_labels_t& labels, const LabelKinematics& k)
      : gen_(rendered.depth_mm.data()), label_(labels.label.data()), k_(k) {}
  int operator()(size_t i) const {
    if (gen_[i] <= 0) return -1;
    const int link = link_of_label(label_[i], k_.num_robot_links, k_.num_links);
    return link >= 0 && link < k_.num_robot_links && k_.link_axis[link] >= 0 ? link : -1;
  }

 private:
  const int16_t* gen_;
  const int16_t* label_;
  const LabelKinematics& k_;
};

// Whether the images and labels agree in size (`pixels` each) and the
// rendered intrinsics can back-project.
bool inputs_usable(const depth_image_t& camera, const depth_image_t& rendered, const link_labels_t& labels,
                   const LabelKinematics& k, size_t pixels) {
  return k.num_joints > 0 && camera.depth_mm.size() == pixels && rendered.depth_mm.size() == pixels &&
         labels.label.size() == pixels && camera.width == rendered.width && rendered.fx > 0 &&
         rendered.fy > 0;
}

// The smallest pixel stride (every k-th row and column) that keeps
// `pixels` within `max_points`.
int stride_within(int64_t pixels, int max_points) {
  int stride = 1;
  while (pixels > int64_t{max_points} * stride * stride) ++stride;
  return stride;
}

// The pixel stride that keeps the moved robot pixels within `max_points`;
// 0 when no pixel shows a moved link.
int sampling_stride(const MovedLinkOf& moved_link, size_t pixels, int max_points) {
  int64_t moved_pixels = 0;
  for (size_t i = 0; i < pixels; ++i) moved_pixels += moved_link(i) >= 0 ? 1 : 0;
  if (moved_pixels == 0) return 0;
  return stride_within(moved_pixels, max_points);
}

// Rendered pixel (u, v) back-projected (optical frame, mm) with its
// 1 / sigma_i: the camera's noise at its depth and the model's own
// (`model_var`, mm^2).
SearchPoint search_point(const depth_image_t& rendered, int u, int v, const DepthNoise& noise,
                         double model_var) {
  const double z = rendered.depth_mm[static_cast<size_t>(v) * rendered.width + u];
  const double sigma_d = noise.sigma_mm(z);
  return SearchPoint{optical_point_m(rendered, u, v, z), 1.0 / std::sqrt(sigma_d * sigma_d + model_var)};
}

using PointsOfLink = std::vector<std::vector<SearchPoint>>;

// The moved robot pixels every `stride`-th row and column, back-projected
// (optical frame, mm) with their 1 / sigma_i, per link; counts them in
// *search_points.
PointsOfLink sample_points(const depth_image_t& rendered, const MovedLinkOf& moved_link, int num_robot_links,
                           const DepthNoise& noise, const EvidenceOptions& options, int stride,
                           int32_t* search_points) {
  PointsOfLink points_of_link(num_robot_links);
  const double model_var = options.model_sigma_mm * options.model_sigma_mm;
  for (int v = 0; v < rendered.height; v += stride) {
    for (int u = 0; u < rendered.width; u += stride) {
      const size_t i = static_cast<size_t>(v) * rendered.width + u;
      const int link = moved_link(i);
      if (link < 0) continue;
      points_of_link[link].push_back(search_point(rendered, u, v, noise, model_var));
      ++*search_points;
    }
  }
  return points_of_link;
}

// A link joint j moves, with j's axes in its chain, distal first (a distal
// axis turns about its line as rendered, before the proximal ones move that
// line).
struct MovedLink {
  const std::vector<SearchPoint>* points;
  std::vector<const LabelAxis*> axes;
};

// The links (with points) joint j moves; *prismatic tells whether j is.
std::vector<MovedLink> links_moved_by(int j, const LabelKinematics& k, const PointsOfLink& points_of_link,
                                      bool* prismatic) {
  std::vector<MovedLink> moved;
  for (int l = 0; l < k.num_robot_links; ++l) {
    if (points_of_link[l].empty()) continue;
    MovedLink m{&points_of_link[l], {}};
    for (int a = k.link_axis[l]; a >= 0; a = k.axes[a].parent) {
      if (k.axes[a].joint != j) continue;
      m.axes.push_back(&k.axes[a]);
      *prismatic = k.axes[a].prismatic;
    }
    if (!m.axes.empty()) moved.push_back(std::move(m));
  }
  return moved;
}

// The rigid motion of link m for a joint offset (rad; m for a prismatic
// joint, whose axes move in mm).
Eigen::Isometry3d link_motion(const MovedLink& m, double offset) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  for (const LabelAxis* axis : m.axes) {
    const double unit = axis->prismatic ? 1000.0 : 1.0;
    motion = axis_motion(*axis, axis->multiplier * offset * unit) * motion;
  }
  return motion;
}

// Each joint's search: the coarse trials (every `coarse_every`-th point
// of each link the joint moves, no more than about kCoarsePoints of the
// joint's points in all: they only pick the basin) over +-range in
// steps, then every point at no offset and, when a trial beat no offset,
// at the best trial and a quarter and a half step either side of it.
// The trials of all joints are one list of tasks (WorkerPool), each
// writing its own cost: a base joint's trials move every robot point and
// a wrist's a few, so tasks per joint left one thread with most of the
// work. The choices below read the costs in a fixed order, so nothing
// depends on the threads.
struct JointTrials {
  std::vector<MovedLink> moved;
  size_t coarse_every = 1;
  double step = 0;
  int steps = 0;
  size_t first_coarse = 0;  // index of its first coarse cost (offset 0)
  size_t first_fine = 0;    // index of its first fine cost (none, then kFine)
};
// The fine trials about the coarse trials' best, in steps.
constexpr double kFine[] = {0.0, -0.5, -0.25, 0.25, 0.5};
struct Trial {
  int joint;
  double offset;
  size_t every;
};

// Each joint's moved links and steps (in *trials_of), and the coarse
// trials of all joints: per joint, no offset first, then -steps..steps.
std::vector<Trial> plan_coarse_trials(const LabelKinematics& k, const PointsOfLink& points_of_link,
                                      const EvidenceOptions& options, std::vector<JointTrials>* trials_of) {
  trials_of->assign(k.num_joints, JointTrials{});
  std::vector<Trial> coarse;
  for (int j = 0; j < k.num_joints; ++j) {
    JointTrials& t = (*trials_of)[j];
    bool prismatic = false;
    t.moved = links_moved_by(j, k, points_of_link, &prismatic);
    if (t.moved.empty()) continue;
    size_t moved_points = 0;
    for (const MovedLink& m : t.moved) moved_points += m.points->size();
    // At most kCoarsePoints (rounded up: a joint moving 2 999 points takes
    // every second, not all of them).
    t.coarse_every = std::max<size_t>(1, (moved_points + kCoarsePoints - 1) / kCoarsePoints);
    const double range = prismatic ? options.search_range_m : options.search_range_rad;
    t.step = prismatic ? options.search_step_m : options.search_step_rad;
    t.steps = static_cast<int>(std::floor(range / t.step + 1e-9));
    t.first_coarse = coarse.size();
    coarse.push_back(Trial{j, 0.0, t.coarse_every});
    for (int g = -t.steps; g <= t.steps; ++g) {
      if (g != 0) coarse.push_back(Trial{j, g * t.step, t.coarse_every});
    }
  }
  return coarse;
}

// Runs lists of trials, on the workers when there are some.
//
// Only the least cost of a joint's trials is ever used, with the cost of
// its trial at no offset in the fine ones (the gain). So a trial stops,
// with cost +infinity, once its partial cost is above the least cost
// finished so far among its joint's trials (PointCost::link_cost,
// kPruneMargin: then the whole one is above it too): the least-cost trial and any trial
// tied with it never stop, whichever thread finished what first, so the
// choices below are the same as without the bound. `exact` (the fine
// trials' no-offset one, whose cost the gain needs) never stops.
class TrialRunner {
 public:
  TrialRunner(const PointCost& cost, const std::vector<JointTrials>& trials_of, WorkerPool* workers)
      : cost_(cost), trials_of_(trials_of), workers_(workers) {}

  // `side` (optional) runs as task 0, the trials as 1.. (the longest task
  // first).
  void run(const std::vector<Trial>& trials, std::vector<double>* costs, SideTask* side,
           const std::vector<uint8_t>& exact) const {
    costs->assign(trials.size(), 0.0);
    std::vector<std::atomic<double>> least(trials_of_.size());
    for (std::atomic<double>& l : least) l.store(std::numeric_limits<double>::infinity());
    const int first = side != nullptr ? 1 : 0;
    const auto one = [&](int task) {
      if (task < first) {
        side->run_once();
        return;
      }
      const auto n = static_cast<size_t>(task - first);
      const Trial& trial = trials[n];
      std::atomic<double>& joint_least = least[static_cast<size_t>(trial.joint)];
      const double bound =
          exact.empty() || exact[n] == 0 ? joint_least.load() : std::numeric_limits<double>::infinity();
      const double sum = trial_cost(trial, bound * (1.0 + kPruneMargin));
      (*costs)[n] = sum;
      double least_now = joint_least.load();
      while (sum < least_now && !joint_least.compare_exchange_weak(least_now, sum)) {
      }
    };
    run_tasks(workers_, first + static_cast<int>(trials.size()), one);
  }

 private:
  // The trial's cost, +infinity once it exceeds `prune_above`.
  double trial_cost(const Trial& trial, double prune_above) const {
    // Scratch, kept by each thread from call to call (no allocation once
    // they have grown).
    thread_local std::vector<double> point_cost;
    thread_local std::vector<double> link_costs;
    const std::vector<MovedLink>& moved = trials_of_[trial.joint].moved;
    link_costs.assign(moved.size(), 0.0);
    // The links from the last (the distal ones, which an offset moves
    // most), the finished cost summed over them in order.
    double seen = 0;
    bool left = false;
    for (size_t l = moved.size(); l-- > 0 && !left;) {
      left = !cost_.link_cost(*moved[l].points, link_motion(moved[l], trial.offset), trial.every, seen,
                              prune_above, &point_cost, &link_costs[l]);
      seen += link_costs[l];
    }
    if (left) return std::numeric_limits<double>::infinity();
    double sum = 0;
    for (const double c : link_costs) sum += c;
    return sum;
  }

  const PointCost& cost_;
  const std::vector<JointTrials>& trials_of_;
  WorkerPool* workers_;
};

// Per joint, the coarse trials' best offset (in *centre_of; 0: none beat
// no offset), and the fine trials: no offset, then kFine about that best.
std::vector<Trial> plan_fine_trials(const std::vector<double>& coarse_cost,
                                    std::vector<JointTrials>* trials_of, std::vector<double>* centre_of) {
  centre_of->assign(trials_of->size(), 0.0);
  std::vector<Trial> fine;
  for (size_t j = 0; j < trials_of->size(); ++j) {
    JointTrials& t = (*trials_of)[j];
    if (t.moved.empty()) continue;
    size_t n = t.first_coarse;
    double coarse_best = coarse_cost[n++];
    double centre = 0;
    for (int g = -t.steps; g <= t.steps; ++g) {
      if (g == 0) continue;
      const double c = coarse_cost[n++];
      if (c < coarse_best) {
        coarse_best = c;
        centre = g * t.step;
      }
    }
    (*centre_of)[j] = centre;
    t.first_fine = fine.size();
    fine.push_back(Trial{static_cast<int>(j), 0.0, 1});
    if (centre == 0) continue;
    for (double f : kFine) fine.push_back(Trial{static_cast<int>(j), centre + f * t.step, 1});
  }
  return fine;
}

// Which fine trials are computed whole: each joint's at no offset (the
// gain).
std::vector<uint8_t> exact_fine_trials(const std::vector<JointTrials>& trials_of, size_t fine_trials) {
  std::vector<uint8_t> exact(fine_trials, 0);
  for (const JointTrials& t : trials_of) {
    if (!t.moved.empty()) exact[t.first_fine] = 1;
  }
  return exact;
}

// Each joint's best fine offset and its gain over no offset, into s.
void choose_offsets(const std::vector<JointTrials>& trials_of, const std::vector<double>& centre_of,
                    const std::vector<double>& fine_cost, discrepancy_t* s) {
  for (size_t j = 0; j < trials_of.size(); ++j) {
    const JointTrials& t = trials_of[j];
    if (t.moved.empty()) continue;
    const double none = fine_cost[t.first_fine];
    double best = none;
    double best_offset = 0;
    if (centre_of[j] != 0) {
      for (size_t f = 0; f < std::size(kFine); ++f) {
        const double c = fine_cost[t.first_fine + 1 + f];
        if (c < best) {
          best = c;
          best_offset = centre_of[j] + kFine[f] * t.step;
        }
      }
    }
    s->joint_search_offset[j] = best_offset;
    s->joint_search_gain[j] = std::max(0.0, none - best);
  }
}

// The joint with the greatest positive gain (the first of equals); -1 for
// none.
int best_joint(const discrepancy_t& s, int num_joints) {
  int best = -1;
  for (int j = 0; j < num_joints; ++j) {
    if (s.joint_search_gain[j] > 0 && (best < 0 || s.joint_search_gain[j] > s.joint_search_gain[best]))
      best = j;
  }
  return best;
}

// The camera as a candidate (discrepancy_t.camera_search_*): one axis of
// its optical frame at a time, as the joints are one at a time, so that
// the gains compare one parameter with one. Translations over the joints'
// prismatic range in twice their step; rotations over +-5 deg in 0.5 deg
// steps (the camera tests' delta is 0.5-1 deg; a larger tilt moves the arm
// out of the search's reach anyway). The fine trials as the joints'.
constexpr int kCameraAxes = 6;
// The camera candidate is tried when the best joint's gain reaches this
// (chi^2): 5 sigma of one parameter (noise alone, chi^2 with 1 degree of
// freedom, reaches it on 6e-7 of frames; nominal frames' gains stay below
// 20, evidence_test). It decides nothing by itself: it keeps the 6 x 20
// camera trials off nominal frames, where a joint's gain of a few (a wrist
// at 1 deg for chi^2 2) is common.
constexpr double kCameraCandidateMinGain = 25.0;
constexpr double kCameraSearchRangeRad = 5.0 * M_PI / 180.0;
constexpr double kCameraSearchStepRad = 0.5 * M_PI / 180.0;

// How the configured optical frame's points look from a camera moved by
// `amount` along (axes 0..2, m) or about (3..5, rad) axis `axis`, seen -
// configured: the camera at configured * M sees the point p at M^-1 p (mm).
Eigen::Isometry3d camera_move_seen(int axis, double amount) {
  Eigen::Isometry3d seen = Eigen::Isometry3d::Identity();
  if (axis < 3) {
    seen.translation()[axis] = -1000.0 * amount;
  } else {
    seen.linear() = Eigen::AngleAxisd(-amount, Eigen::Vector3d::Unit(axis - 3)).toRotationMatrix();
  }
  return seen;
}

// The rendered pixels no joint moves (the environment, fixed links) every
// `stride`-th row and column, back-projected (search_point).
std::vector<SearchPoint> sample_static_points(const depth_image_t& rendered, const MovedLinkOf& moved_link,
                                              const DepthNoise& noise, const EvidenceOptions& options,
                                              int stride) {
  std::vector<SearchPoint> points;
  const int16_t* gen = rendered.depth_mm.data();
  const double model_var = options.model_sigma_mm * options.model_sigma_mm;
  for (int v = 0; v < rendered.height; v += stride) {
    for (int u = 0; u < rendered.width; u += stride) {
      const size_t i = static_cast<size_t>(v) * rendered.width + u;
      if (gen[i] <= 0 || moved_link(i) >= 0) continue;
      points.push_back(search_point(rendered, u, v, noise, model_var));
    }
  }
  return points;
}

// The static pixels' stride that keeps them within `max_points`.
int static_stride(const depth_image_t& rendered, const MovedLinkOf& moved_link, int max_points) {
  int64_t pixels = 0;
  for (size_t i = 0; i < rendered.depth_mm.size(); ++i) {
    pixels += rendered.depth_mm[i] > 0 && moved_link(i) < 0 ? 1 : 0;
  }
  return stride_within(pixels, max_points);
}

// The points a camera move is tried on, each set with its own cost (its
// own sampling weight), and every how many of them a coarse trial takes.
struct CameraCandidatePoints {
  std::vector<SearchPoint> robot;
  std::vector<SearchPoint> scene;
  size_t robot_every = 1;
  size_t scene_every = 1;
};

struct CameraTrial {
  int axis;
  double amount;
  bool coarse;
};

// The costs of `trials`, each one task (on the workers when there are
// some); no pruning, so each is the whole sum.
std::vector<double> camera_trial_costs(const std::vector<CameraTrial>& trials, const CameraCandidatePoints& p,
                                       const PointCost& robot_cost, const PointCost& scene_cost,
                                       WorkerPool* workers) {
  std::vector<double> costs(trials.size(), 0.0);
  const double never = std::numeric_limits<double>::infinity();
  const auto one = [&](int task) {
    thread_local std::vector<double> point_cost;
    const CameraTrial& t = trials[static_cast<size_t>(task)];
    const Eigen::Isometry3d seen = camera_move_seen(t.axis, t.amount);
    double robot = 0, scene = 0;
    robot_cost.link_cost(p.robot, seen, t.coarse ? p.robot_every : 1, 0, never, &point_cost, &robot);
    scene_cost.link_cost(p.scene, seen, t.coarse ? p.scene_every : 1, 0, never, &point_cost, &scene);
    costs[static_cast<size_t>(task)] = robot + scene;
  };
  run_tasks(workers, static_cast<int>(trials.size()), one);
  return costs;
}

// The step of a camera axis's trials (m or rad) and their number each side.
double camera_step(int axis, const EvidenceOptions& options, int* steps) {
  const double range = axis < 3 ? options.search_range_m : kCameraSearchRangeRad;
  const double step = axis < 3 ? 2 * options.search_step_m : kCameraSearchStepRad;
  *steps = step > 0 ? static_cast<int>(std::floor(range / step + 1e-9)) : 0;
  return step;
}

// The camera candidate (see kCameraAxes): coarse trials per axis, then the
// fine ones about each axis's best, into s->camera_search_*.
void search_camera_move(const depth_image_t& camera, const depth_image_t& rendered,
                        const MovedLinkOf& moved_link, const PointsOfLink& points_of_link,
                        const PointCost& robot_cost, const DepthNoise& noise, const EvidenceOptions& options,
                        WorkerPool* workers, discrepancy_t* s) {
  CameraCandidatePoints p;
  for (const std::vector<SearchPoint>& link : points_of_link)
    p.robot.insert(p.robot.end(), link.begin(), link.end());
  const int stride = static_stride(rendered, moved_link, options.search_max_points);
  p.scene = sample_static_points(rendered, moved_link, noise, options, stride);
  s->camera_search_static_points = static_cast<int32_t>(p.scene.size());
  p.robot_every = std::max<size_t>(1, (p.robot.size() + kCoarsePoints - 1) / kCoarsePoints);
  p.scene_every = std::max<size_t>(1, (p.scene.size() + kCoarsePoints - 1) / kCoarsePoints);
  const PointCost scene_cost(camera, rendered, options.clip_sigmas,
                             static_cast<double>(stride) * stride / options.pixels_per_sample);
  // Coarse: no move first, then each axis's steps.
  std::vector<CameraTrial> coarse{{0, 0.0, true}};
  for (int axis = 0; axis < kCameraAxes; ++axis) {
    int steps = 0;
    const double step = camera_step(axis, options, &steps);
    for (int g = -steps; g <= steps; ++g) {
      if (g != 0) coarse.push_back(CameraTrial{axis, g * step, true});
    }
  }
  const std::vector<double> coarse_cost = camera_trial_costs(coarse, p, robot_cost, scene_cost, workers);
  // Fine: no move first, then kFine about each axis's coarse best (none
  // for an axis where no move beat none).
  std::vector<CameraTrial> fine{{0, 0.0, false}};
  size_t n = 1;
  for (int axis = 0; axis < kCameraAxes; ++axis) {
    int steps = 0;
    const double step = camera_step(axis, options, &steps);
    double best = coarse_cost[0];
    double centre = 0;
    for (int g = -steps; g <= steps; ++g) {
      if (g == 0) continue;
      if (coarse_cost[n] < best) {
        best = coarse_cost[n];
        centre = g * step;
      }
      ++n;
    }
    if (centre == 0) continue;
    for (double f : kFine) fine.push_back(CameraTrial{axis, centre + f * step, false});
  }
  if (fine.size() == 1) return;
  const std::vector<double> fine_cost = camera_trial_costs(fine, p, robot_cost, scene_cost, workers);
  // The least cost of all (the first of equals), its gain over no move.
  size_t best = 0;
  for (size_t k = 1; k < fine.size(); ++k) {
    if (fine_cost[k] < fine_cost[best]) best = k;
  }
  if (best == 0) return;
  s->camera_search_axis = static_cast<int8_t>(fine[best].axis);
  s->camera_search_offset = fine[best].amount;
  s->camera_search_gain = std::max(0.0, fine_cost[0] - fine_cost[best]);
}

}  // namespace

void search_joint_offsets(const depth_image_t& camera, const depth_image_t& rendered,
                          const link_labels_t& labels, const LabelKinematics& k, const DepthNoise& noise,
                          const EvidenceOptions& options, discrepancy_t* summary,
                          std::vector<uint8_t>* explained_static, WorkerPool* workers, SideTask* beside) {
  if (explained_static != nullptr) explained_static->clear();
  discrepancy_t& s = *summary;
  s.search_points = 0;
  s.joint_search_offset.assign(k.num_joints, 0.0);
  s.joint_search_gain.assign(k.num_joints, 0.0);
  s.camera_search_static_points = 0;
  s.camera_search_axis = -1;
  s.camera_search_offset = 0;
  s.camera_search_gain = 0;
  const size_t pixels =
      static_cast<size_t>(std::max(rendered.width, 0)) * static_cast<size_t>(std::max(rendered.height, 0));
  if (!inputs_usable(camera, rendered, labels, k, pixels)) return;
  // The robot pixels a joint moves, and the stride that keeps them within
  // search_max_points.
  const MovedLinkOf moved_link(rendered, labels, k);
  const int stride = sampling_stride(moved_link, pixels, options.search_max_points);
  if (stride == 0) return;
  const PointsOfLink points_of_link =
      sample_points(rendered, moved_link, k.num_robot_links, noise, options, stride, &s.search_points);
  const PointCost cost(camera, rendered, options.clip_sigmas,
                       static_cast<double>(stride) * stride / options.pixels_per_sample);

  std::vector<JointTrials> trials_of;
  const std::vector<Trial> coarse = plan_coarse_trials(k, points_of_link, options, &trials_of);
  const TrialRunner runner(cost, trials_of, workers);
  std::vector<double> coarse_cost;
  runner.run(coarse, &coarse_cost, beside, {});
  std::vector<double> centre_of;
  const std::vector<Trial> fine = plan_fine_trials(coarse_cost, &trials_of, &centre_of);
  std::vector<double> fine_cost;
  runner.run(fine, &fine_cost, nullptr, exact_fine_trials(trials_of, fine.size()));
  choose_offsets(trials_of, centre_of, fine_cost, &s);
  const int joint = best_joint(s, k.num_joints);
  // The camera as a candidate, where a joint's offset explains much.
  if (joint >= 0 && s.joint_search_gain[joint] >= kCameraCandidateMinGain) {
    search_camera_move(camera, rendered, moved_link, points_of_link, cost, noise, options, workers, &s);
  }

  // The static pixels the best joint's offset explains: where its moved
  // points land and match the measured depth.
  if (explained_static == nullptr) return;
  explained_static->assign(pixels, 0);
  if (joint < 0) return;
  const auto is_static = [&](int i) { return moved_link(static_cast<size_t>(i)) < 0; };
  for (const MovedLink& m : trials_of[joint].moved) {
    cost.mark_matches(*m.points, link_motion(m, s.joint_search_offset[joint]), stride, is_static,
                      explained_static);
  }
}

}  // namespace tofguard::discrepancy
