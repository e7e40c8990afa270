# ctest's install_consumer: installs the build into a fresh prefix, checks the installed command line reports the
# project's version and writes images, then configures, builds and runs the consumer project against that prefix alone.
# cmake -DBUILD_DIR=... -DCONSUMER_DIR=... -DWORK_DIR=... -DVERSION=... -DCXX=... [-DBUILD_TYPE=...]
#       [-DSANITIZE_FLAGS=...] [-DLAUNCHER=ccache] -P run.cmake
foreach(var BUILD_DIR CONSUMER_DIR WORK_DIR VERSION CXX)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "install consumer: ${var} is not set")
  endif()
endforeach()

function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${out}${err}")
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "install consumer: ${what} failed (${status})")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

set(prefix "${WORK_DIR}/prefix")
file(REMOVE_RECURSE "${WORK_DIR}")
step("cmake --install" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}")

step("installed trm --version" "${prefix}/bin/trm" --version)
if(NOT step_output MATCHES "trm ${VERSION}")
  message(FATAL_ERROR "install consumer: installed trm --version printed '${step_output}', not trm ${VERSION}")
endif()
foreach(installed include/trm/decoder.hpp include/trm/fixed_decoder.hpp include/trm/encoder.hpp include/trm/panel.hpp
                  include/trm/fixed.hpp include/trm/link.hpp include/trm/media.hpp lib/cmake/trm/trmConfig.cmake
                  lib/cmake/trm/trmConfigVersion.cmake lib/trm/libtrm_media.so)
  if(NOT EXISTS "${prefix}/${installed}")
    message(FATAL_ERROR "install consumer: ${installed} was not installed under ${prefix}")
  endif()
endforeach()

# The installed trm writes its PNGs through the installed media plugin, found relative to itself.
step("installed trm run" "${prefix}/bin/trm" run --scene discs --size 16x12 --frames 2 --out "${WORK_DIR}/run")
if(NOT EXISTS "${WORK_DIR}/run/pair_sent_full.png")
  message(FATAL_ERROR "install consumer: the installed trm run wrote no pair_sent_full.png")
endif()

# A sanitizer build's static libraries need the sanitizer runtime in whatever links them.
set(flags "")
if(SANITIZE_FLAGS)
  set(flags "-DCMAKE_CXX_FLAGS=${SANITIZE_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${SANITIZE_FLAGS}")
endif()
if(LAUNCHER)
  list(APPEND flags "-DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}")
endif()
if(NOT BUILD_TYPE)
  set(BUILD_TYPE Release)
endif()
step("configuring the consumer" "${CMAKE_COMMAND}" -S "${CONSUMER_DIR}" -B "${WORK_DIR}/build"
     "-DCMAKE_PREFIX_PATH=${prefix}" "-DCMAKE_CXX_COMPILER=${CXX}" "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}" ${flags})
step("building the consumer" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
step("running the consumer" "${WORK_DIR}/build/consumer" "${WORK_DIR}/drive_codes.png")
file(REMOVE_RECURSE "${WORK_DIR}")
