// The renderer in steady state takes no large block from the heap.
//
// Mesa's llvmpipe (the renderer on a machine without a GPU driver, and in
// CI) copies a draw's changed uniforms into a 1 MB upload buffer and
// allocates a new buffer (posix_memalign, 1 MB) whenever one is full. When
// depth_renderer.cpp set the mesh pose and label as uniforms per draw, that
// was one new megabyte every ~345 frames of config/sim.yaml's arm; in
// tofguard-renderer, whose heap keeps its memory (keep_heap_resident), the
// freed buffers were split by small blocks and its RSS grew by 1 MB steps
// (soak_test measured 2-4 MB in two minutes on CI). This test counts the
// process's aligned allocations of at least 512 kB while the renderer draws
// 2000 frames after a warm-up: none may come.
//
// It replaces posix_memalign for the whole process (an executable's
// definition takes precedence over libc's for every library, Mesa's too)
// and passes every call on to the next definition. Not under the
// sanitizers, which intercept the allocator themselves: skipped there.
#include <gtest/gtest.h>

#include <dlfcn.h>

#include <atomic>
#include <cmath>
#include <cstddef>

#include "estimator_test_support.hpp"
#include "scaled_intrinsics.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/renderer_service.hpp"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define TOFGUARD_ALLOCATOR_INTERCEPTED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define TOFGUARD_ALLOCATOR_INTERCEPTED 1
#endif
#endif

#ifndef TOFGUARD_ALLOCATOR_INTERCEPTED
namespace {

constexpr size_t kLargeBlockBytes = 512 * 1024;
std::atomic<bool> counting{false};
std::atomic<int> large_aligned_blocks{0};

}  // namespace

extern "C" int posix_memalign(void** block, size_t alignment, size_t size) {
  using PosixMemalign = int (*)(void**, size_t, size_t);
  static const PosixMemalign next = reinterpret_cast<PosixMemalign>(dlsym(RTLD_NEXT, "posix_memalign"));
  if (counting.load(std::memory_order_relaxed) && size >= kLargeBlockBytes) large_aligned_blocks++;
  return next(block, alignment, size);
}
#endif

namespace tofguard::renderer {
namespace {

TEST(RendererHeap, SteadyStateFramesTakeNoLargeBlock) {
#ifdef TOFGUARD_ALLOCATOR_INTERCEPTED
  GTEST_SKIP() << "the sanitizer intercepts posix_memalign: allocations are counted in the plain build only";
#else
  const deployment::Config config = estimator::test::sim_config();
  const robot_model::SceneModel scene = robot_model::load_scene(
      config.robot.urdf_path, config.environment.urdf_paths, scene_options(config.renderer, config.robot));
  DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  // Half the camera's size: the draws per frame are the same (what filled
  // llvmpipe's upload buffer), the rasterising cheaper.
  const Intrinsics intrinsics = tofguard::test::scaled_intrinsics(
      config.camera.intrinsics, config.camera.intrinsics.width / 2, config.camera.intrinsics.height / 2);
  const robot_model::JointPositions centre = estimator::test::reach_pose();
  const auto frame = [&](int i) {
    robot_model::JointPositions q = centre;
    for (auto& [name, angle_rad] : q) angle_rad += 0.3 * std::sin(0.01 * i + name.back());
    const RenderResult r = renderer.render(q, config.camera.pose, intrinsics);
    ASSERT_TRUE(r.usable) << r.unusable_reason;
  };
  for (int i = 0; i < 50; ++i) frame(i);  // warm-up: shaders, framebuffer, the first upload buffer
  if (HasFatalFailure()) return;
  counting = true;
  for (int i = 50; i < 2050; ++i) {
    frame(i);
    if (HasFatalFailure()) break;
  }
  counting = false;
  EXPECT_EQ(large_aligned_blocks.load(), 0) << "aligned blocks of at least " << kLargeBlockBytes / 1024
                                            << " kB taken in 2000 frames (" << renderer.description() << ")";
#endif
}

}  // namespace
}  // namespace tofguard::renderer
