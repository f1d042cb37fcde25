# The installable package: `cmake --install build --prefix P` puts
#   P/lib/libvrelab_*.a                    the stage libraries (static, see below)
#   P/include/vrelab/<stage>/.../*.hpp     the public headers, at their source-tree paths
#   P/include/vrelab/vrelab_version.hpp    the generated version header
#   P/bin/vrelab                           the program
#   P/share/vrelab/plots/*.py              the plot scripts (the program finds them at
#                                          <its folder>/../share/vrelab/plots)
#   P/lib/cmake/vrelab/vrelabConfig.cmake  + version file and the exported targets
# A consumer writes find_package(vrelab) and links vrelab::vrelab (all stages) or one stage
# (vrelab::core, vrelab::plant, vrelab::vibration, vrelab::rectification,
# vrelab::validation, vrelab::formats, vrelab::services). Its include directory is P/include/vrelab, so it includes
# the headers as the project's own code does: #include "rectification/prediction/eq3.hpp".
# (The stage folders keep generic names such as io/ and core/: they live under vrelab/ so
# that an install into /usr/local does not claim /usr/local/include/io.)
#
# Static libraries, the default of add_library here: the program and the tests run the same
# object code as a plain executable build (no -fPIC, no calls through the PLT in the ODE's
# inner loop), and the installed program needs no RPATH or LD_LIBRARY_PATH, so the prefix can
# be moved. The price is that a consumer links the private dependencies too (SUNDIALS' CVODE,
# FFTW, fmt, toml++): vrelabConfig.cmake finds them with find_dependency, so a consumer's
# CMakeLists does not name them; on Debian they are the -dev packages setup.sh installs.
# -DBUILD_SHARED_LIBS=ON gives shared libraries instead (the installed program then finds
# them through its RPATH, $ORIGIN/../lib); a Python module will need position-independent
# code either way.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(VRELAB_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/vrelab)
set(VRELAB_INSTALL_INCLUDEDIR ${CMAKE_INSTALL_INCLUDEDIR}/vrelab)
set(VRELAB_PLOTS_SUBDIR share/vrelab/plots)  # fixed: io/formats/output.cpp's run_plot_script looks there

# The plot scripts in the build tree at the installed layout's relative place
# (build/share/vrelab/plots beside build/vrelab), refreshed when a script changes.
function(vrelab_copy_plot_scripts)
  file(GLOB scripts CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tools/plots/*.py)
  set(copies)
  foreach(script IN LISTS scripts)
    get_filename_component(name ${script} NAME)
    set(copy ${PROJECT_BINARY_DIR}/${VRELAB_PLOTS_SUBDIR}/${name})
    add_custom_command(OUTPUT ${copy} COMMAND ${CMAKE_COMMAND} -E copy_if_different ${script} ${copy}
                       DEPENDS ${script} COMMENT "Plot script ${name} -> ${VRELAB_PLOTS_SUBDIR}" VERBATIM)
    list(APPEND copies ${copy})
  endforeach()
  add_custom_target(vrelab_plots ALL DEPENDS ${copies})
  add_dependencies(vrelab vrelab_plots)
endfunction()

# The stage CMakeLists state their usage requirements for the build tree (include directory
# = the source tree, the warnings target linked privately). This turns them into what the
# installed targets need, in one place for all stages: source and build paths are kept for
# the build tree only ($<BUILD_INTERFACE:...>) and P/include/vrelab is added for the install;
# the private link to vrelab_warnings (a static library records its private links as
# $<LINK_ONLY:...>) is dropped from the link interface: it carries compile options only.
function(vrelab_prepare_for_export)
  foreach(target IN LISTS ARGN)
    get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
    set(fixed)
    foreach(dir IN LISTS dirs)
      if(dir MATCHES "^\\$<")
        list(APPEND fixed "${dir}")
      elseif(dir)
        list(APPEND fixed "$<BUILD_INTERFACE:${dir}>")
      endif()
    endforeach()
    list(APPEND fixed "$<INSTALL_INTERFACE:${VRELAB_INSTALL_INCLUDEDIR}>")
    list(REMOVE_DUPLICATES fixed)
    set_property(TARGET ${target} PROPERTY INTERFACE_INCLUDE_DIRECTORIES "${fixed}")
    get_target_property(libs ${target} INTERFACE_LINK_LIBRARIES)
    if(libs)
      list(REMOVE_ITEM libs vrelab_warnings "$<LINK_ONLY:vrelab_warnings>")
      set_property(TARGET ${target} PROPERTY INTERFACE_LINK_LIBRARIES "${libs}")
    endif()
  endforeach()
endfunction()

function(vrelab_install_package)
  # library target vrelab_<name> -> exported name vrelab::<name>; io/ holds two (formats, services)
  set(stages core plant vibration rectification validation io)
  set(libraries core plant vibration rectification validation formats services)
  set(targets)
  foreach(name IN LISTS libraries)
    list(APPEND targets vrelab_${name})
    set_target_properties(vrelab_${name} PROPERTIES EXPORT_NAME ${name})
    add_library(vrelab::${name} ALIAS vrelab_${name})
  endforeach()
  vrelab_prepare_for_export(${targets})
  # What a consumer's compile and link need beyond the include directory: C++20 (the headers
  # use it), and the sanitizer runtime when the libraries are instrumented with it.
  target_compile_features(vrelab_core INTERFACE cxx_std_20)
  if(VRELAB_SANITIZE)
    target_link_options(vrelab_core INTERFACE -fsanitize=address,undefined)
  endif()

  # The umbrella: every stage (io/services links all of them).
  add_library(vrelab_library INTERFACE)
  target_link_libraries(vrelab_library INTERFACE vrelab_services)
  set_target_properties(vrelab_library PROPERTIES EXPORT_NAME vrelab)
  add_library(vrelab::vrelab ALIAS vrelab_library)

  install(TARGETS ${targets} vrelab_library EXPORT vrelabTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(TARGETS vrelab RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  if(BUILD_SHARED_LIBS)
    set_target_properties(vrelab PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
  endif()

  # Headers of every stage at their source-tree paths (a new header is installed without a
  # change here); app/ is the program's, not the library's.
  foreach(stage IN LISTS stages)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/${stage}/ DESTINATION ${VRELAB_INSTALL_INCLUDEDIR}/${stage}
            FILES_MATCHING PATTERN "*.hpp")
  endforeach()
  install(FILES ${PROJECT_BINARY_DIR}/generated/vrelab_version.hpp DESTINATION ${VRELAB_INSTALL_INCLUDEDIR})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/tools/plots/ DESTINATION ${VRELAB_PLOTS_SUBDIR}
          FILES_MATCHING PATTERN "*.py")

  install(EXPORT vrelabTargets NAMESPACE vrelab:: DESTINATION ${VRELAB_INSTALL_CMAKEDIR})
  set(VRELAB_STATIC ON)
  if(BUILD_SHARED_LIBS)
    set(VRELAB_STATIC OFF)
  endif()
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/vrelabConfig.cmake.in
                                ${PROJECT_BINARY_DIR}/cmake/vrelabConfig.cmake
                                INSTALL_DESTINATION ${VRELAB_INSTALL_CMAKEDIR})
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/vrelabConfigVersion.cmake
                                   COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/cmake/vrelabConfig.cmake ${PROJECT_BINARY_DIR}/cmake/vrelabConfigVersion.cmake
          DESTINATION ${VRELAB_INSTALL_CMAKEDIR})
endfunction()
