# Writes the commit a `plume` program is built from into a C++ source (`plume version`), run as a
# script at every build: cmake -DSOURCE_DIR=... -DOUTPUT=... -P PlumeBuildInfo.cmake.
#
# The commit comes from git when the source is a git checkout (with "-dirty" when tracked files
# differ from it); else from cmake/source_commit.txt, which `git archive` fills in (export-subst in
# .gitattributes), so a release tarball without .git knows its commit too; else "unknown". The
# output is rewritten only when its text changes, so a build that changes nothing compiles nothing.
if(NOT SOURCE_DIR OR NOT OUTPUT)
  message(FATAL_ERROR "PlumeBuildInfo.cmake: expected -DSOURCE_DIR=... -DOUTPUT=...")
endif()

set(commit "")
find_program(PLUME_GIT git)
if(PLUME_GIT AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${PLUME_GIT}" -C "${SOURCE_DIR}" rev-parse --short=12 HEAD
                  OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE failed)
  if(failed)
    set(commit "")
  else()
    execute_process(COMMAND "${PLUME_GIT}" -C "${SOURCE_DIR}" status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE changes OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(changes)
      string(APPEND commit "-dirty")
    endif()
  endif()
endif()
if(NOT commit AND EXISTS "${SOURCE_DIR}/cmake/source_commit.txt")
  file(STRINGS "${SOURCE_DIR}/cmake/source_commit.txt" archived LIMIT_COUNT 1)
  # Unexpanded ($Format:...$) outside an archive.
  if(archived MATCHES "^[0-9a-f]+$")
    string(SUBSTRING "${archived}" 0 12 commit)
  endif()
endif()
if(NOT commit)
  set(commit "unknown")
endif()

set(text "// Written by cmake/PlumeBuildInfo.cmake at build time.\nextern const char *const plume_source_commit = \"${commit}\";\n")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" previous)
endif()
if(NOT previous STREQUAL text)
  file(WRITE "${OUTPUT}" "${text}")
endif()
