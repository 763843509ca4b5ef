# `cmake --install build --prefix DIR` puts the `plume` program, Plume's static libraries and their
# public headers in DIR, and exports a CMake package: a project that calls
#   find_package(Plume REQUIRED)   # with DIR in CMAKE_PREFIX_PATH
# links Plume::pipeline (load a groom, produce frames), Plume::io (groom files, meshes, strand
# files) and the stages (Plume::interp, Plume::effects, ...), each bringing what it needs.
include(CMakePackageConfigHelpers)

# Every library, in dependency order. Its folder holds its public headers (installed as
# include/plume/<folder>/*.h, included as "<folder>/<name>.h", as inside Plume).
set(PLUME_INSTALLED_LIBRARIES
  groom:plume_groom skin:plume_skin partings:plume_partings interp:plume_interp effects:plume_effects
  check:plume_check dynamics:plume_dynamics controls:plume_controls feathers:plume_feathers io:plume_io app:plume_pipeline)

foreach(entry ${PLUME_INSTALLED_LIBRARIES})
  string(REPLACE ":" ";" parts ${entry})
  list(GET parts 0 folder)
  list(GET parts 1 target)
  string(REGEX REPLACE "^plume_" "" export_name ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  install(TARGETS ${target} EXPORT PlumeTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  if(folder STREQUAL "app")
    # Of app/, only the pipeline's headers are a library's; the rest is the command.
    set(headers ${PROJECT_SOURCE_DIR}/app/pipeline.h ${PROJECT_SOURCE_DIR}/app/frame_range.h)
  else()
    file(GLOB headers ${PROJECT_SOURCE_DIR}/${folder}/*.h)
  endif()
  install(FILES ${headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/plume/${folder})
endforeach()
install(TARGETS plume RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

install(EXPORT PlumeTargets NAMESPACE Plume:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Plume)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/PlumeConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/PlumeConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Plume PATH_VARS CMAKE_INSTALL_BINDIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/PlumeConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/PlumeConfig.cmake ${PROJECT_BINARY_DIR}/PlumeConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Plume)
