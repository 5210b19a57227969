# The libFuzzer tree (TOFGUARD_FUZZ=ON, included from the top-level
# CMakeLists.txt; scripts/fuzz configures it with clang in build-fuzz/).
# It builds only what the targets below reach: the LCM headers, common/
# (decoding, wire checks, the YAML reader), robot_model/ (URDF, assimp),
# auth/, the config loader with the settings libraries, and spy's message
# formatter. Everything is compiled with AddressSanitizer,
# UndefinedBehaviorSanitizer and libFuzzer's coverage instrumentation, so a
# bug in tofguard's own code is seen where it happens; the system libraries
# (lcm, yaml-cpp, urdfdom, assimp) are the Debian builds, not instrumented.
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "TOFGUARD_FUZZ needs clang (scripts/fuzz sets CMAKE_CXX_COMPILER=clang++-14)")
endif()

# -fno-sanitize-recover: a UB report stops the run like a crash does, so the
# input is saved. Assertions stay on (no NDEBUG): Eigen's index checks are
# part of what is tested.
set(TOFGUARD_SANITIZERS -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
add_compile_options(${TOFGUARD_SANITIZERS} -fsanitize=fuzzer-no-link -O1 -g)
add_link_options(-fsanitize=address,undefined)

add_subdirectory(lcmtypes)
add_subdirectory(common)
add_subdirectory(robot_model)

set(fuzz_dir ${CMAKE_CURRENT_LIST_DIR})

# The config loader (deployment/) on the settings libraries (settings/),
# auth/ for the config's key and the signed envelopes, and tofguard-spy's
# formatter, which decodes every message type it sees: their own targets,
# which link no component's logic (no EGL, OpenCV, libuvc or libusb).
add_subdirectory(auth)
add_subdirectory(settings)
add_subdirectory(deployment)
add_subdirectory(spy)

# tofguard_fuzz_target(NAME <name> LIBS <...>): tests/fuzz/<name>_fuzz.cpp
# as a libFuzzer binary bin/<name>_fuzz.
function(tofguard_fuzz_target)
  cmake_parse_arguments(ARG "" "NAME" "LIBS" ${ARGN})
  add_executable(${ARG_NAME}_fuzz ${fuzz_dir}/${ARG_NAME}_fuzz.cpp)
  target_include_directories(${ARG_NAME}_fuzz PRIVATE ${fuzz_dir})
  target_compile_definitions(${ARG_NAME}_fuzz PRIVATE TOFGUARD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_link_libraries(${ARG_NAME}_fuzz PRIVATE ${ARG_LIBS})
  target_link_options(${ARG_NAME}_fuzz PRIVATE -fsanitize=fuzzer)
endfunction()

tofguard_fuzz_target(NAME wire_messages LIBS tofguard_common tofguard_auth)
tofguard_fuzz_target(NAME spy_format LIBS tofguard_spy)
tofguard_fuzz_target(NAME config LIBS tofguard_deployment)
tofguard_fuzz_target(NAME urdf LIBS tofguard_scene_model)
tofguard_fuzz_target(NAME mesh LIBS tofguard_scene_model)

# Seeds that cannot be written by hand: one valid encoded message of each
# type (their fingerprints change with the .lcm files, so they are made at
# build time rather than committed). scripts/fuzz runs it.
add_executable(make_wire_seeds ${fuzz_dir}/make_wire_seeds.cpp)
target_include_directories(make_wire_seeds PRIVATE ${fuzz_dir})
target_link_libraries(make_wire_seeds PRIVATE tofguard_lcmtypes tofguard_auth)
