# Precompiled headers (build time only; docs/performance.md, "Build time").
#
# Most of a small translation unit's compile is parsing the headers every file includes: the
# standard library's and Eigen's (and gtest's in the tests, fmt's and nlohmann/json's in io/).
# Precompiled once per group of targets that share their flags, they are loaded instead of
# parsed. Only third-party and standard headers: a change in the project's own headers rebuilds
# no precompiled header. PRIVATE: the installed package's targets carry no trace of them
# (cmake/VrelabPackage.cmake exports INTERFACE properties only). -DVRELAB_PCH=OFF builds
# without (each file then must, and does, include what it uses: the OFF build is the check).
#
# ccache: a precompiled header is used by ccache only with sloppiness pch_defines,time_macros
# (and include_file_mtime,include_file_ctime, or ccache refuses the just-made header as too
# new). When the C++ launcher is ccache, the targets here get them through the environment of
# their compiles (CCACHE_SLOPPINESS, which replaces ccache.conf's sloppiness for those compiles).
option(VRELAB_PCH "Precompile the standard, Eigen, fmt, nlohmann/json and gtest headers (build time only)" ON)

set(VRELAB_PCH_STD <algorithm> <array> <cmath> <complex> <cstdint> <cstdio> <filesystem> <fstream> <functional>
    <limits> <map> <memory> <numbers> <optional> <random> <sstream> <stdexcept> <string> <utility> <vector>)
set(VRELAB_CCACHE_SLOPPINESS pch_defines,time_macros,include_file_mtime,include_file_ctime)

# vrelab_precompile_headers(<target> HEADERS <header>...): <target>'s own precompiled header,
# the standard headers above and <header>... (as #include names: <Eigen/Dense>).
# vrelab_precompile_headers(<target> REUSE_FROM <other>): <other>'s, for a target compiled with
# the same flags (GCC's -Winvalid-pch, an error with VRELAB_WERROR, says when it is not).
function(vrelab_precompile_headers target)
  if(NOT VRELAB_PCH)
    return()
  endif()
  cmake_parse_arguments(PCH "" "REUSE_FROM" "HEADERS" ${ARGN})
  if(PCH_REUSE_FROM)
    target_precompile_headers(${target} REUSE_FROM ${PCH_REUSE_FROM})
  else()
    target_precompile_headers(${target} PRIVATE ${VRELAB_PCH_STD} ${PCH_HEADERS})
  endif()
  if(CMAKE_CXX_COMPILER_LAUNCHER)
    list(GET CMAKE_CXX_COMPILER_LAUNCHER 0 launcher)
    get_filename_component(launcher_name "${launcher}" NAME)
    if(launcher_name STREQUAL "ccache")
      set_property(TARGET ${target} PROPERTY CXX_COMPILER_LAUNCHER
                   ${CMAKE_COMMAND} -E env CCACHE_SLOPPINESS=${VRELAB_CCACHE_SLOPPINESS} ${CMAKE_CXX_COMPILER_LAUNCHER})
    endif()
  endif()
endfunction()
