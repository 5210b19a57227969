# The product's precompiled header, reused by every library and executable
# of the tree that has none of its own (the test executables reuse
# tests/CMakeLists.txt's tofguard_test_pch): Eigen (127k lines preprocessed,
# through the settings headers), LCM's C++ header and the standard headers
# most files include, parsed once for the tree instead of in each of its
# ~120 other files. A library file with GCC: risk_monitor.cpp 2.2 -> 1.6 s,
# frame_classifier.cpp 2.1 -> 1.3 s (docs/reliability.md, "CI time").
#
# The header is built with the tree's own flags; a file built with others
# (another -O, another -f) is refused (CMake adds -Winvalid-pch, an error
# with -Werror), never a silent slow build. A file that forgets one of these
# includes still builds here; the fuzz tree (tests/fuzz/FuzzTree.cmake)
# compiles common/, robot_model/ and the config readers without the header,
# and only system headers are in it (no project declaration can stand in
# for another, as in the unity build docs/reliability.md turned down).
add_library(tofguard_pch OBJECT ${CMAKE_CURRENT_LIST_DIR}/product_pch.cpp)
target_link_libraries(tofguard_pch PRIVATE Eigen3::Eigen)
target_precompile_headers(tofguard_pch PRIVATE
  <Eigen/Core> <Eigen/Geometry> <lcm/lcm-cpp.hpp>
  <algorithm> <atomic> <chrono> <cmath> <cstdint> <functional> <iostream> <map> <memory>
  <optional> <sstream> <string> <vector>)

include(TargetsBelow)
tofguard_targets_below(${PROJECT_SOURCE_DIR} tofguard_all_targets)
foreach(target ${tofguard_all_targets})
  get_target_property(type ${target} TYPE)
  if(NOT type MATCHES "^(STATIC_LIBRARY|EXECUTABLE)$")
    continue()
  endif()
  get_target_property(reuse ${target} PRECOMPILE_HEADERS_REUSE_FROM)
  get_target_property(own ${target} PRECOMPILE_HEADERS)
  if(reuse OR own)
    continue()
  endif()
  # C++ only (the header is C++).
  get_target_property(sources ${target} SOURCES)
  set(cxx_only TRUE)
  foreach(source ${sources})
    if(NOT source MATCHES "\\.(cpp|cc|hpp|h)$")
      set(cxx_only FALSE)
    endif()
  endforeach()
  if(NOT cxx_only)
    continue()
  endif()
  # (Eigen3::Eigen: the header's include path.)
  target_link_libraries(${target} PRIVATE Eigen3::Eigen)
  target_precompile_headers(${target} REUSE_FROM tofguard_pch)
endforeach()
