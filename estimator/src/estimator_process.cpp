#include "tofguard/estimator/estimator_process.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>

#include "tofguard/common/config_error.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/state_history_settings.hpp"
#include "tofguard/robot_model/kinematics.hpp"

namespace tofguard::estimator {

ProcessInfo process_info() {
  return {
      "tofguard-estimator",
      "Estimates which joint offsets and which camera-pose correction best explain the camera's depth image "
      "(docs/estimator.md): TOF_DEPTH, JOINT_STATE, CAMERA_POSE, SAFETY_DISCREPANCY, SAFETY_RISK -> "
      "MOTION_ESTIMATE, for every frame whose discrepancy passes the warning level or that tofguard-risk "
      "judged a model mismatch, and periodically."};
}

EstimatorOptions options_from_settings(const EstimatorProcessSettings& settings) {
  EstimatorOptions o;
  o.estimate_joints = settings.estimator.estimate_joints;
  o.estimate_camera = settings.estimator.estimate_camera;
  o.noise_sigma_at_0m_m = std::max(1e-4, settings.noise_sigma_at_0m_mm / 1000.0);
  o.noise_sigma_per_m2_m = settings.noise_sigma_per_m2_mm / 1000.0;
  o.max_iterations = settings.estimator.max_iterations;
  o.pixel_stride = settings.estimator.pixel_stride;
  return o;
}

robot_model::SceneModel load_estimator_scene(const EstimatorProcessSettings& settings) {
  robot_model::SceneOptions options;
  options.geometry = robot_model::GeometrySource::kVisual;
  options.padding_m = 0;
  options.package_paths = settings.robot.package_paths;
  return robot_model::load_scene(settings.robot.urdf_path, settings.environment.urdf_paths, options);
}

EstimatorScheduler::EstimatorScheduler(const EstimatorProcessSettings& settings,
                                       const robot_model::SceneModel& scene)
    : settings_(settings),
      scene_(scene),
      state_(renderer::state_history_settings(settings.renderer, settings.robot.id, settings.camera)) {}

bool EstimatorScheduler::on_joint_state(const joint_state_t& state) {
  // A frame waiting for its joints may now be ready.
  return state_.add_joint_state(state);
}

void EstimatorScheduler::on_camera_pose(const camera_pose_t& message) { state_.add_camera_pose(message); }

bool EstimatorScheduler::on_depth(const depth_image_t& frame) {
  if (frame.camera_id != settings_.camera.id) return false;
  frames_[frame.seq] = frame;
  while (static_cast<int>(frames_.size()) > settings_.estimator.max_pending_frames) {
    const int64_t oldest = frames_.begin()->first;
    if (wanted_.count(oldest) > 0) {
      wanted_.erase(oldest);
      ++missed_;
    }
    frames_.erase(frames_.begin());
  }
  while (!warning_seqs_.empty() && *warning_seqs_.begin() < frames_.begin()->first) {
    warning_seqs_.erase(warning_seqs_.begin());
  }
  // Wanted seqs older than every kept frame will never come.
  while (!wanted_.empty() && wanted_.begin()->first < frames_.begin()->first) {
    wanted_.erase(wanted_.begin());
    ++missed_;
  }
  while (estimated_.size() > 1000) estimated_.erase(estimated_.begin());
  const auto w = wanted_.find(frame.seq);
  if (w != wanted_.end()) {
    ready_.push_back(build(frame, w->second));
    estimated_.insert(frame.seq);
    wanted_.erase(w);
  }
  return true;
}

bool EstimatorScheduler::passes_warning(const discrepancy_t& d) const {
  // The estimator's own thresholds on the published summary (estimator.
  // warning); tofguard-risk's verdicts add the frames its rules judge a
  // model mismatch (on_risk).
  return d.mismatch_fraction >= settings_.estimator.warning_mismatch_fraction ||
         d.p95_abs_dis_mm >= settings_.estimator.warning_p95_abs_dis_mm;
}

void EstimatorScheduler::on_discrepancy(const discrepancy_t& d) {
  if (d.camera_id != settings_.camera.id || !d.usable) return;
  if (passes_warning(d)) on_warning(d.seq, d.utime);
}

void EstimatorScheduler::on_risk(const risk_t& r) {
  // Timeouts (seq -1) are about no frame; faults are not the model's.
  if (r.seq < 0 || r.level < risk_t::WARNING || !is_model_mismatch(r.cause)) return;
  // A verdict on a frame kept with another utime is not about that frame
  // (a camera restarted its seqs).
  const auto f = frames_.find(r.seq);
  if (f != frames_.end() && f->second.utime != r.utime) return;
  on_warning(r.seq, r.utime);
}

void EstimatorScheduler::on_warning(int64_t seq, int64_t utime) {
  if (frames_.empty() || seq >= frames_.begin()->first) warning_seqs_.insert(seq);
  if (estimated_.count(seq) > 0) return;
  const int64_t min_interval_us = settings_.estimator.warning_min_interval_us;
  if (last_warning_utime_ > 0 && utime >= last_warning_utime_ &&
      utime - last_warning_utime_ < min_interval_us) {
    return;  // rate limit (camera time)
  }
  last_warning_utime_ = utime;
  const auto f = frames_.find(seq);
  if (f != frames_.end()) {
    ready_.push_back(build(f->second, motion_estimate_t::TRIGGER_WARNING));
    estimated_.insert(seq);
  } else if (frames_.empty() || seq > frames_.begin()->first) {
    wanted_[seq] = motion_estimate_t::TRIGGER_WARNING;
  } else {
    ++missed_;
  }
}

void EstimatorScheduler::request_newest() {
  if (frames_.empty()) return;
  const auto newest = std::prev(frames_.end());
  if (estimated_.count(newest->first) > 0) return;
  ready_.push_back(build(newest->second, motion_estimate_t::TRIGGER_PERIODIC));
  estimated_.insert(newest->first);
}

std::vector<ScheduledWork> EstimatorScheduler::take_ready() {
  std::vector<ScheduledWork> out;
  out.swap(ready_);
  return out;
}

std::optional<EstimatorFrame> EstimatorScheduler::estimator_frame(const depth_image_t& frame,
                                                                  const std::string& frame_id,
                                                                  std::string* why) const {
  const robot_state::StateAtFrame state = state_.at(frame.camera_id, frame.utime);
  if (!state.joints.usable) {
    *why = "joint state: " + state.joints.unusable_reason;
    return std::nullopt;
  }
  const robot_state::PoseAtTime& pose = state.camera_pose;
  if (!pose.usable) {
    *why = "camera pose: " + pose.unusable_reason;
    return std::nullopt;
  }
  if (pose.pose.frame_id != frame_id) {
    *why = "camera pose frame changed from '" + frame_id + "' to '" + pose.pose.frame_id + "'";
    return std::nullopt;
  }
  const int frame_link = scene_.find_link(frame_id);
  if (frame_link < 0) {
    *why = "camera pose frame '" + frame_id + "' is not a model link";
    return std::nullopt;
  }
  // A camera on a moving link would move with the joints being estimated:
  // not modelled.
  const std::string moving = scene_.nearest_movable_joint_above(frame_id);
  if (!moving.empty()) {
    *why = "camera pose frame '" + frame_id + "' moves with joint '" + moving +
           "': a camera on the arm is not supported by the estimator";
    return std::nullopt;
  }
  const robot_model::LinkPoses poses = robot_model::forward_kinematics(scene_, state.joints.joints);
  if (!poses.usable) {
    *why = poses.unusable_reason;
    return std::nullopt;
  }
  EstimatorFrame out;
  out.intrinsics = intrinsics_of(frame);
  out.reported_joints = state.joints.joints;
  out.world_from_optical = poses.world_from_link[frame_link] * pose.pose.frame_from_optical();
  out.depth_m = depth_m_of(frame);
  return out;
}

ScheduledWork EstimatorScheduler::build(const depth_image_t& frame, int8_t trigger) const {
  ScheduledWork work;
  EstimateContext context;
  context.utime = frame.utime;
  context.seq = frame.seq;
  context.camera_id = frame.camera_id;
  context.trigger = trigger;
  context.joint_names = scene_.actuated_joint_names;
  const robot_state::StateAtFrame state = state_.at(frame.camera_id, frame.utime);
  if (state.camera_pose.usable) {
    context.frame_id = state.camera_pose.pose.frame_id;
    context.frame_from_optical = state.camera_pose.pose.frame_from_optical();
  }
  const robot_model::JointPositions& joints = state.joints.joints;
  for (const std::string& name : context.joint_names) {
    const auto found = joints.find(name);
    context.reported_positions.push_back(found != joints.end() ? found->second : 0.0);
  }
  std::string why;
  std::optional<EstimatorFrame> first = estimator_frame(frame, context.frame_id, &why);
  if (!first) {
    work.unusable = unusable_message(context, why);
    return work;
  }
  EstimateJob job;
  job.context = context;
  job.frames.push_back(std::move(*first));
  // The kept frames just before it, newest first, that can be estimated
  // with it: on the same side of a fault's onset (warning or not), joints
  // and pose known, same size and pose frame.
  const bool warning = trigger == motion_estimate_t::TRIGGER_WARNING || warning_seqs_.count(frame.seq) > 0;
  for (auto it = frames_.lower_bound(frame.seq);
       it != frames_.begin() &&
       static_cast<int>(job.frames.size()) < settings_.estimator.frames_per_estimate;) {
    --it;
    const depth_image_t& earlier = it->second;
    if ((warning_seqs_.count(it->first) > 0) != warning) continue;
    if (earlier.width != frame.width || earlier.height != frame.height) continue;
    std::optional<EstimatorFrame> f = estimator_frame(earlier, context.frame_id, &why);
    if (f) job.frames.push_back(std::move(*f));
  }
  work.job = std::move(job);
  return work;
}

EstimatorWorker::EstimatorWorker(const robot_model::SceneModel& scene,
                                 const EstimatorProcessSettings& settings)
    : scene_(scene), settings_(settings), thread_([this] { run(); }) {}

EstimatorWorker::~EstimatorWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

std::string EstimatorWorker::wait_ready() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!wake_.wait_for(lock, std::chrono::seconds(30), [&] { return started_; })) {
    return "the estimator's renderer did not start within 30 s";
  }
  return start_error_;
}

bool EstimatorWorker::post(EstimateJob job) {
  bool dropped;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    dropped = pending_.has_value();
    pending_ = std::move(job);
  }
  wake_.notify_all();
  return dropped;
}

std::vector<motion_estimate_t> EstimatorWorker::take_results() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<motion_estimate_t> out;
  out.swap(results_);
  return out;
}

bool EstimatorWorker::busy() {
  std::lock_guard<std::mutex> lock(mutex_);
  return working_ || pending_.has_value();
}

void EstimatorWorker::run() {
  std::unique_ptr<renderer::DepthRenderer> renderer;
  std::unique_ptr<MotionEstimator> estimator;
  try {
    // The renderer's GL context belongs to this thread.
    renderer = std::make_unique<renderer::DepthRenderer>(scene_, settings_.renderer.near_m,
                                                         settings_.renderer.far_m);
    estimator = std::make_unique<MotionEstimator>(scene_, renderer.get(), options_from_settings(settings_));
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    start_error_ = e.what();
    started_ = true;
    wake_.notify_all();
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    started_ = true;
  }
  wake_.notify_all();
  while (true) {
    EstimateJob job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
      if (stop_) return;
      job = std::move(*pending_);
      pending_.reset();
      working_ = true;
    }
    const EstimateResult result = estimator->estimate(job.frames);
    motion_estimate_t message = to_message(result, job.context);
    std::lock_guard<std::mutex> lock(mutex_);
    results_.push_back(std::move(message));
    working_ = false;
  }
}

int run_estimator(const EstimatorProcessSettings& settings) {
  const std::string name = process_info().name;
  // The estimator renders 176x144-sized images a dozen times per frame on
  // its worker thread: llvmpipe's own render threads cost more in hand-over
  // than they save at that size (docs/benchmarks.md, motion estimator: 36 ms
  // per frame without them, 44 ms with). Set before the EGL display is
  // opened; a value in the environment wins.
  setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);
  // The estimate is a diagnosis, not part of the stop path: on a small CPU
  // it must never take time from the renderer, discrepancy and risk, whose
  // deadlines stop the arm. Niceness +10 for the process and every thread
  // it starts (set before any thread exists).
  errno = 0;
  if (nice(10) == -1 && errno != 0) {
    std::cerr << name << ": cannot lower its priority (nice 10): " << std::strerror(errno) << "\n";
  }
  robot_model::SceneModel scene;
  try {
    scene = load_estimator_scene(settings);
  } catch (const std::exception& e) {
    std::cerr << name << ": " << e.what() << "\n";
    return kConfigErrorExitCode;
  }
  EstimatorWorker worker(scene, settings);
  const std::string worker_error = worker.wait_ready();
  if (!worker_error.empty()) {
    std::cerr << name << ": cannot start the estimator: " << worker_error << "\n";
    return 1;
  }
  EstimatorScheduler scheduler(settings, scene);
  LcmNode node(settings.lcm, settings.channels, name);
  node.heartbeat().set_status("waiting for frames");
  int64_t published = 0;
  int64_t unusable = 0;

  auto dispatch = [&] {
    for (ScheduledWork& work : scheduler.take_ready()) {
      if (work.unusable) {
        node.safety().publish(settings.channels.motion_estimate, &*work.unusable);
        node.counters().frames_out++;
        ++unusable;
        node.errors().report("unusable", "frame " + std::to_string(work.unusable->seq) +
                                             " not estimated: " + work.unusable->unusable_reason);
      } else if (work.job && worker.post(std::move(*work.job))) {
        // Behind: the waiting job was replaced by this newer one.
        node.counters().frames_dropped++;
      }
    }
  };

  node.subscribe<joint_state_t>(
      node.safety(), settings.channels.joint_state,
      [&](const joint_state_t& state) {
        if (!scheduler.on_joint_state(state)) {
          node.counters().validation_errors++;
          node.errors().report(settings.channels.joint_state,
                               settings.channels.joint_state + ": ignored a message for robot_id '" +
                                   state.robot_id + "' (expected '" + settings.robot.id +
                                   "') or not newer than the last");
        }
      },
      check_joint_state);
  node.subscribe<camera_pose_t>(
      node.safety(), settings.channels.camera_pose,
      [&](const camera_pose_t& pose) { scheduler.on_camera_pose(pose); }, check_camera_pose);
  node.subscribe<depth_image_t>(
      node.images(), settings.channels.depth,
      [&](const depth_image_t& frame) {
        if (scheduler.on_depth(frame)) {
          node.heartbeat().set_last_frame_utime(frame.utime);
          dispatch();
        }
      },
      check_depth_image);
  node.subscribe<discrepancy_t>(
      node.safety(), settings.channels.discrepancy,
      [&](const discrepancy_t& d) {
        scheduler.on_discrepancy(d);
        dispatch();
      },
      check_discrepancy);
  node.subscribe<risk_t>(
      node.safety(), settings.channels.risk,
      [&](const risk_t& r) {
        scheduler.on_risk(r);
        dispatch();
      },
      check_risk);
  node.add_timer(settings.estimator.periodic_period_us, [&] {
    scheduler.request_newest();
    dispatch();
  });
  node.add_timer(5000, [&] {
    for (const motion_estimate_t& m : worker.take_results()) {
      node.safety().publish(settings.channels.motion_estimate, &m);
      node.counters().frames_out++;
      ++published;
      if (!m.usable) ++unusable;
    }
    node.heartbeat().set_status("estimates " + std::to_string(published) + ", unusable " +
                                std::to_string(unusable) + ", missed " + std::to_string(scheduler.missed()) +
                                (worker.busy() ? ", estimating" : ", idle"));
  });
  node.run();
  return 0;
}

}  // namespace tofguard::estimator
