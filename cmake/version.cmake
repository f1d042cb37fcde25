# Writes the version header with the current git commit; run at every build (see the
# top-level CMakeLists.txt), so a result never records the commit of an older configure.
# configure_file leaves the header untouched when nothing changed (no needless rebuild).
execute_process(COMMAND git describe --always --dirty --abbrev=12
                WORKING_DIRECTORY ${SOURCE_DIR}
                OUTPUT_VARIABLE VRELAB_GIT_DESCRIBE OUTPUT_STRIP_TRAILING_WHITESPACE
                ERROR_QUIET)
if(NOT VRELAB_GIT_DESCRIBE)
  set(VRELAB_GIT_DESCRIBE "unknown")
endif()
configure_file(${SOURCE_DIR}/app/version.hpp.in ${OUTPUT} @ONLY)
