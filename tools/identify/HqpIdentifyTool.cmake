# hqp_add_identify_tool(<executable> MODEL <model target> ROBOT <ns::Robot> [HEADER <file>])
#
# Builds tools/identify.cpp for one robot model made by hqp_add_robot_model()
# (docs/identification.md). Identification uses joint torques of a robot on a
# fixed rig, so the model must be generated WITHOUT FLOATING_BASE (the root
# link, e.g. the torso, fixed to the world). HEADER defaults to <model target>.hpp.
# Needs NLopt (Debian: libnlopt-cxx-dev), CLI11 and urdfdom.
include_guard(GLOBAL)
set(_HQP_IDENTIFY_SOURCE "${CMAKE_CURRENT_LIST_DIR}/../identify.cpp")

function(hqp_add_identify_tool exe)
  cmake_parse_arguments(ARG "" "MODEL;ROBOT;HEADER" "" ${ARGN})
  if(NOT ARG_MODEL OR NOT ARG_ROBOT)
    message(FATAL_ERROR "hqp_add_identify_tool(${exe}): MODEL and ROBOT are required")
  endif()
  if(NOT ARG_HEADER)
    set(ARG_HEADER "${ARG_MODEL}.hpp")
  endif()
  add_executable(${exe} ${_HQP_IDENTIFY_SOURCE})
  target_compile_definitions(${exe} PRIVATE
    HQP_IDENTIFY_HEADER="${ARG_HEADER}" HQP_IDENTIFY_ROBOT=${ARG_ROBOT})
  target_link_libraries(${exe} PRIVATE ${ARG_MODEL} NLopt::nlopt CLI11::CLI11 urdfdom::urdfdom_model)
  target_compile_options(${exe} PRIVATE -Wall -Wextra)
endfunction()
