# Installs the build BUILD_DIR into WORK_DIR/prefix and uses it as a robot team would, with
# nothing from the source tree but the small projects under TEST_DIR:
#   1. the installed files are where docs/install.md says;
#   2. pkg-config --cflags/--modversion hqp compile a program that prints the version;
#   3. find_package(hqp COMPONENTS ...): known ones give their targets, the core target links
#      Eigen only, an unknown one fails the configure;
#   4. user_project/: Walker3 model from the installed URDF (hqp_add_robot_model), controller
#      from the installed YAML, ticks on synthetic standing data;
#   5. generator_project/: hqp_add_robot_model with FRAMES on a small URDF of the user's.
# Variables: BUILD_DIR, WORK_DIR, TEST_DIR, VERSION, PKG_CONFIG, CXX, HAVE_IDENT, FUSED_PAIR_URDF.
cmake_minimum_required(VERSION 3.25)
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
# Only this prefix: no package registry, no other hqp elsewhere on the system; the
# compiler of the build under test.
set(find_args "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
              -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF "-DCMAKE_CXX_COMPILER=${CXX}")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed: ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

# 1. Install and look at the files.
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")
foreach(f include/hqp_wbc/hqp/version.hpp include/hqp_wbc/model/robot_dynamics.hpp
          include/hqp_wbc/tasks/controller.hpp share/pkgconfig/hqp.pc share/doc/hqp/LICENSE
          share/hqp/robots/walker3/walker3.urdf share/hqp/robots/walker3/controller.yaml
          lib/cmake/hqp/hqpConfig.cmake lib/cmake/hqp/hqp_yamlTargets.cmake bin/hqp_urdf2model)
  if(NOT EXISTS "${prefix}/${f}")
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
file(READ "${prefix}/include/hqp_wbc/hqp/version.hpp" header)
if(NOT header MATCHES "#define HQP_VERSION_STRING \"${VERSION}\"")
  message(FATAL_ERROR "installed hqp/version.hpp does not say ${VERSION}")
endif()
message(STATUS "1. installed files: ok")

# 2. pkg-config, from the installed .pc only.
set(ENV{PKG_CONFIG_PATH} "${prefix}/share/pkgconfig")
run(${PKG_CONFIG} --modversion hqp)
string(STRIP "${out}" modversion)
if(NOT modversion STREQUAL VERSION)
  message(FATAL_ERROR "pkg-config --modversion hqp: '${modversion}', expected '${VERSION}'")
endif()
run(${PKG_CONFIG} --cflags hqp)
string(STRIP "${out}" cflags)
separate_arguments(cflags UNIX_COMMAND "${cflags}")
message(STATUS "pkg-config --cflags hqp: ${cflags}")
file(MAKE_DIRECTORY "${WORK_DIR}/pc")
run(${CXX} -std=c++17 ${cflags} "${TEST_DIR}/pkg_config_main.cpp" -o "${WORK_DIR}/pc/pc_app")
run("${WORK_DIR}/pc/pc_app")
if(NOT out STREQUAL "hqp ${VERSION}\n")
  message(FATAL_ERROR "pkg-config program printed '${out}'")
endif()
message(STATUS "2. pkg-config: ok")

# 3. Components.
set(components yaml)
if(HAVE_IDENT)
  list(APPEND components ident)
endif()
string(REPLACE ";" "," components_arg "${components}")
run(${CMAKE_COMMAND} -S "${TEST_DIR}/components" -B "${WORK_DIR}/components_ok" ${find_args}
    "-DWANT=${components_arg}")
run(${CMAKE_COMMAND} -S "${TEST_DIR}/components" -B "${WORK_DIR}/components_core" ${find_args} -DWANT=)
execute_process(COMMAND ${CMAKE_COMMAND} -S "${TEST_DIR}/components" -B "${WORK_DIR}/components_bad"
                        ${find_args} "-DWANT=yaml,no_such_part"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT "${out}${err}" MATCHES "unknown component 'no_such_part'")
  message(FATAL_ERROR "find_package(hqp REQUIRED COMPONENTS no_such_part) did not fail as it should:\n${out}\n${err}")
endif()
message(STATUS "3. components: ok")

# 4. The user's project. No build type: -O0 keeps the one controller TU cheap to compile,
# and leaves Eigen's assertions on.
run(${CMAKE_COMMAND} -S "${TEST_DIR}/user_project" -B "${WORK_DIR}/user_build" ${find_args}
    -DCMAKE_BUILD_TYPE=)
run(${CMAKE_COMMAND} --build "${WORK_DIR}/user_build")
run("${WORK_DIR}/user_build/stand" "${prefix}/share/hqp/robots/walker3/controller.yaml")
message(STATUS "4. user project:\n${out}")
if(NOT out MATCHES "ok: 10 ticks")
  message(FATAL_ERROR "the user project did not report success")
endif()

# 5. The generator on the user's own URDF, with an extra frame.
run(${CMAKE_COMMAND} -S "${TEST_DIR}/generator_project" -B "${WORK_DIR}/generator_build" ${find_args}
    "-DROBOT_URDF=${FUSED_PAIR_URDF}")
run(${CMAKE_COMMAND} --build "${WORK_DIR}/generator_build")
run("${WORK_DIR}/generator_build/app")
if(NOT out STREQUAL "nv=7 nframes=3\n")
  message(FATAL_ERROR "generator project printed '${out}'")
endif()
message(STATUS "5. generator project: ok")
