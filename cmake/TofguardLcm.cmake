# LCM 1.3.1 on Debian 12 ships no lcmConfig.cmake: find its parts by hand.
find_program(LCM_GEN lcm-gen REQUIRED)
find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp REQUIRED)
find_library(LCM_LIBRARY lcm REQUIRED)
# The Java classes are for lcm-spy only: a build that needs only the C++
# headers (the clang fuzz tree, tests/fuzz/) sets TOFGUARD_LCM_JAVA OFF.
option(TOFGUARD_LCM_JAVA "Generate and build the LCM types' Java classes (lcm-spy)" ON)
if(TOFGUARD_LCM_JAVA)
  find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java REQUIRED NO_DEFAULT_PATH)
  find_package(Java 11 REQUIRED COMPONENTS Development)
endif()

# cmake/lcm_wire_schema.py writes the types' wire layout (see there).
find_package(Python3 REQUIRED COMPONENTS Interpreter)
set(TOFGUARD_LCM_WIRE_SCHEMA_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/lcm_wire_schema.py)

add_library(lcm::lcm UNKNOWN IMPORTED)
set_target_properties(lcm::lcm PROPERTIES
  IMPORTED_LOCATION ${LCM_LIBRARY}
  INTERFACE_INCLUDE_DIRECTORIES ${LCM_INCLUDE_DIR})

# tofguard_lcm_types(TARGET <name> JAR <path> FILES <a.lcm> ...)
# Generates C++ headers (c++11), <PACKAGE>/wire_schema.hpp (every type's
# wire layout, for decode_message's bounds check) and Java classes into the build tree at build
# time, builds the Java classes into JAR (unless TOFGUARD_LCM_JAVA is OFF), and defines the INTERFACE library
# TARGET that carries the headers' include path and -llcm.
function(tofguard_lcm_types)
  cmake_parse_arguments(ARG "" "TARGET;JAR;PACKAGE" "FILES" ${ARGN})
  set(cpp_dir ${CMAKE_CURRENT_BINARY_DIR}/cpp)
  set(java_dir ${CMAKE_CURRENT_BINARY_DIR}/java)
  set(class_dir ${CMAKE_CURRENT_BINARY_DIR}/classes)
  set(headers "")
  set(java_sources "")
  foreach(lcm_file ${ARG_FILES})
    get_filename_component(type_name ${lcm_file} NAME_WE)
    list(APPEND headers ${cpp_dir}/${ARG_PACKAGE}/${type_name}.hpp)
    list(APPEND java_sources ${java_dir}/${ARG_PACKAGE}/${type_name}.java)
  endforeach()
  set(schema ${cpp_dir}/${ARG_PACKAGE}/wire_schema.hpp)
  add_custom_command(
    OUTPUT ${schema}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${cpp_dir}/${ARG_PACKAGE}
    COMMAND ${Python3_EXECUTABLE} ${TOFGUARD_LCM_WIRE_SCHEMA_SCRIPT} ${ARG_PACKAGE} ${schema} ${ARG_FILES}
    DEPENDS ${ARG_FILES} ${TOFGUARD_LCM_WIRE_SCHEMA_SCRIPT}
    COMMENT "lcm_wire_schema.py: wire layout of ${ARG_PACKAGE}"
    VERBATIM)
  if(NOT TOFGUARD_LCM_JAVA)
    add_custom_command(
      OUTPUT ${headers}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${cpp_dir}
      COMMAND ${LCM_GEN} --cpp --cpp-std c++11 --cpp-hpath ${cpp_dir} ${ARG_FILES}
      DEPENDS ${ARG_FILES}
      COMMENT "lcm-gen: C++ for ${ARG_PACKAGE}"
      VERBATIM)
    add_custom_target(${ARG_TARGET}_generated ALL DEPENDS ${headers} ${schema})
  else()
    add_custom_command(
      OUTPUT ${headers} ${java_sources}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${cpp_dir} ${java_dir}
      COMMAND ${LCM_GEN} --cpp --cpp-std c++11 --cpp-hpath ${cpp_dir} ${ARG_FILES}
      COMMAND ${LCM_GEN} --java --jpath ${java_dir} ${ARG_FILES}
      DEPENDS ${ARG_FILES}
      COMMENT "lcm-gen: C++ and Java for ${ARG_PACKAGE}"
      VERBATIM)
    add_custom_command(
      OUTPUT ${ARG_JAR}
      COMMAND ${CMAKE_COMMAND} -E rm -rf ${class_dir}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${class_dir}
      COMMAND ${Java_JAVAC_EXECUTABLE} -nowarn -encoding UTF-8 -cp ${LCM_JAR} -d ${class_dir} ${java_sources}
      COMMAND ${Java_JAR_EXECUTABLE} cf ${ARG_JAR} -C ${class_dir} .
      DEPENDS ${java_sources}
      COMMENT "javac + jar: ${ARG_JAR}"
      VERBATIM)
    add_custom_target(${ARG_TARGET}_generated ALL DEPENDS ${headers} ${schema} ${ARG_JAR})
  endif()
  add_library(${ARG_TARGET} INTERFACE)
  target_include_directories(${ARG_TARGET} INTERFACE ${cpp_dir})
  target_link_libraries(${ARG_TARGET} INTERFACE lcm::lcm)
  add_dependencies(${ARG_TARGET} ${ARG_TARGET}_generated)
endfunction()
