# `cmake --install build --prefix P`: the module libraries as trm::<module>, every module's public headers, the `trm`
# command line, and trmConfig.cmake / trmConfigVersion.cmake so that find_package(trm) finds the libraries and their
# dependencies again. The version is project(trm VERSION ...)'s, the one place it is set.
include(CMakePackageConfigHelpers)

set(trm_installed_modules fixed_point hw_models encoder link decoder)
set(trm_install_cmake_dir "${CMAKE_INSTALL_LIBDIR}/cmake/trm")

foreach(module IN LISTS trm_installed_modules)
  set_target_properties(trm_${module} PROPERTIES EXPORT_NAME ${module})
  add_library(trm::${module} ALIAS trm_${module})
  # The whole include directory, not a list of headers: headers added to a module later are installed with it.
  install(DIRECTORY "${PROJECT_SOURCE_DIR}/${module}/include/" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
endforeach()
list(TRANSFORM trm_installed_modules PREPEND trm_ OUTPUT_VARIABLE trm_installed_targets)

install(TARGETS ${trm_installed_targets} EXPORT trmTargets
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        INCLUDES DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
install(TARGETS trm RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
# The media plugin (trm/media.hpp) in lib/trm/, found by the installed trm relative to itself (so the prefix can
# move) and by consumers through trm::encoder's run path.
install(TARGETS trm_media LIBRARY DESTINATION "${TRM_MEDIA_INSTALL_DIR}")
set_target_properties(trm PROPERTIES INSTALL_RPATH "$ORIGIN/../${TRM_MEDIA_INSTALL_DIR}")
install(EXPORT trmTargets NAMESPACE trm:: DESTINATION "${trm_install_cmake_dir}")

configure_package_config_file("${CMAKE_CURRENT_LIST_DIR}/trmConfig.cmake.in"
                              "${PROJECT_BINARY_DIR}/trmConfig.cmake"
                              INSTALL_DESTINATION "${trm_install_cmake_dir}")
# 0.x: a minor version may change the API, so only the same major.minor is compatible.
write_basic_package_version_file("${PROJECT_BINARY_DIR}/trmConfigVersion.cmake"
                                 VERSION "${PROJECT_VERSION}" COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/trmConfig.cmake" "${PROJECT_BINARY_DIR}/trmConfigVersion.cmake"
        DESTINATION "${trm_install_cmake_dir}")
