# `plume version` names the commit it was built from in a git checkout and in a `git archive`
# tarball without .git (cmake/source_commit.txt, filled in by export-subst), and says "unknown"
# when it can know neither. Runs cmake/PlumeBuildInfo.cmake as the build does, on:
#   1. the source tree itself: HEAD's commit (a checkout), or the archive's (a tarball);
#   2. when the tree is a checkout, a tarball of it made by git archive: the same commit;
#   3. a copy with neither .git nor an archived commit: "unknown".
# cmake -DSOURCE_DIR=... -DSCRATCH=... -P check_build_info.cmake
file(REMOVE_RECURSE "${SCRATCH}")
file(MAKE_DIRECTORY "${SCRATCH}")

function(commit_of source r_commit)
  set(output "${SCRATCH}/build_info.cpp")
  file(REMOVE "${output}")
  execute_process(COMMAND "${CMAKE_COMMAND}" -DSOURCE_DIR=${source} -DOUTPUT=${output}
                          -P "${source}/cmake/PlumeBuildInfo.cmake" RESULT_VARIABLE failed)
  if(failed)
    message(FATAL_ERROR "PlumeBuildInfo.cmake failed on ${source}")
  endif()
  file(READ "${output}" text)
  if(NOT text MATCHES "plume_source_commit = \"([^\"]*)\"")
    message(FATAL_ERROR "no commit in ${output}: ${text}")
  endif()
  set(${r_commit} "${CMAKE_MATCH_1}" PARENT_SCOPE)
endfunction()

find_program(GIT git)
file(STRINGS "${SOURCE_DIR}/cmake/source_commit.txt" archived LIMIT_COUNT 1)
commit_of("${SOURCE_DIR}" tree)
if(GIT AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT}" -C "${SOURCE_DIR}" rev-parse --short=12 HEAD OUTPUT_VARIABLE head
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT tree MATCHES "^${head}(-dirty)?$")
    message(FATAL_ERROR "checkout: expected commit ${head}, got ${tree}")
  endif()
  execute_process(COMMAND "${GIT}" -C "${SOURCE_DIR}" archive --format=tar -o "${SCRATCH}/source.tar" HEAD cmake
                  RESULT_VARIABLE failed)
  if(failed)
    message(FATAL_ERROR "git archive failed")
  endif()
  file(MAKE_DIRECTORY "${SCRATCH}/tarball")
  file(ARCHIVE_EXTRACT INPUT "${SCRATCH}/source.tar" DESTINATION "${SCRATCH}/tarball")
  commit_of("${SCRATCH}/tarball" from_tarball)
  if(NOT from_tarball STREQUAL head)
    message(FATAL_ERROR "tarball: expected commit ${head}, got ${from_tarball}")
  endif()
elseif(archived MATCHES "^[0-9a-f]+$")
  string(SUBSTRING "${archived}" 0 12 expected)
  if(NOT tree STREQUAL expected)
    message(FATAL_ERROR "tarball: expected commit ${expected}, got ${tree}")
  endif()
endif()
file(MAKE_DIRECTORY "${SCRATCH}/bare/cmake")
file(COPY "${SOURCE_DIR}/cmake/PlumeBuildInfo.cmake" DESTINATION "${SCRATCH}/bare/cmake")
file(WRITE "${SCRATCH}/bare/cmake/source_commit.txt" "$Format:%H$\n")
commit_of("${SCRATCH}/bare" bare)
if(NOT bare STREQUAL "unknown")
  message(FATAL_ERROR "neither git nor an archive: expected unknown, got ${bare}")
endif()
message(STATUS "build info: checkout/tarball ${tree}, bare copy ${bare}")
