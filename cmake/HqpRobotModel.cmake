# hqp_add_robot_model(<target> URDF <file> [FLOATING_BASE] [NAMESPACE <ns>] [FRAMES <f>...])
#
# Generates <build>/hqp_models/<target>/<target>.hpp from the URDF at build time
# (again whenever the URDF or the generator changes) and makes <target> an
# INTERFACE library that carries that include directory and links hqp::hqp.
# NAMESPACE defaults to <target>. Format: docs/generated-model.md; rules and
# error messages: docs/adding-a-robot.md.
#
# The generator is the in-tree target hqp_urdf2model when building hqp_wbc
# itself, or the imported hqp::urdf2model of an installed hqp_wbc package.
include_guard(GLOBAL)

function(hqp_add_robot_model target)
  cmake_parse_arguments(ARG "FLOATING_BASE" "URDF;NAMESPACE" "FRAMES" ${ARGN})
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "hqp_add_robot_model(${target}): unknown arguments '${ARG_UNPARSED_ARGUMENTS}'")
  endif()
  if(NOT ARG_URDF)
    message(FATAL_ERROR "hqp_add_robot_model(${target}): URDF <file> is required")
  endif()
  if(TARGET hqp_urdf2model)
    set(tool hqp_urdf2model)
  elseif(TARGET hqp::urdf2model)
    set(tool hqp::urdf2model)
  else()
    message(FATAL_ERROR "hqp_add_robot_model(${target}): the generator hqp_urdf2model is not available "
                        "(build hqp_wbc with HQP_BUILD_TOOLS=ON and install it)")
  endif()
  if(NOT ARG_NAMESPACE)
    set(ARG_NAMESPACE ${target})
  endif()

  get_filename_component(urdf "${ARG_URDF}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  set(dir "${CMAKE_BINARY_DIR}/hqp_models/${target}")
  set(header "${dir}/${target}.hpp")
  set(args "${urdf}" -o "${header}" --namespace "${ARG_NAMESPACE}")
  if(ARG_FLOATING_BASE)
    list(APPEND args --floating-base)
  endif()
  if(ARG_FRAMES)
    list(JOIN ARG_FRAMES "," frames)
    list(APPEND args --frames "${frames}")
  endif()

  file(MAKE_DIRECTORY "${dir}")
  add_custom_command(
    OUTPUT "${header}"
    COMMAND ${tool} ${args}
    DEPENDS "${urdf}" ${tool}
    COMMENT "Generating robot model ${target} from ${ARG_URDF}"
    VERBATIM)
  add_custom_target(${target}_header DEPENDS "${header}")

  add_library(${target} INTERFACE)
  target_include_directories(${target} INTERFACE "${dir}")
  target_link_libraries(${target} INTERFACE hqp::hqp)
  # Dependencies of an INTERFACE library pass on to whatever links it.
  add_dependencies(${target} ${target}_header)
endfunction()
