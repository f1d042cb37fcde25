# python/find.cmake -- included by the top-level CMakeLists.txt before the libraries: finds
# Python and pybind11 (Debian: pybind11-dev, python3-dev) and sets VRELAB_PYTHON_MODULE. When
# found, the static libraries are built position-independent (they link into the module).
# The interpreter is Debian's /usr/bin/python3 unless Python_EXECUTABLE is given: a pyenv or
# venv python3 first on PATH may lack NumPy or be another version.
if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python_EXECUTABLE /usr/bin/python3)
endif()
set(VRELAB_PYTHON_MODULE OFF)
if(VRELAB_SANITIZE)
  # An ASan-instrumented module loads only with the ASan runtime preloaded into the
  # interpreter: the sanitizer build leaves the module (and its tests) out.
  message(STATUS "vrelab: no Python module in the sanitizer build")
  return()
endif()
find_package(Python 3.8 COMPONENTS Interpreter Development.Module QUIET)
if(Python_FOUND)
  set(PYBIND11_FINDPYTHON ON)
  find_package(pybind11 2.6 CONFIG QUIET)
endif()
if(Python_FOUND AND pybind11_FOUND)
  set(VRELAB_PYTHON_MODULE ON)
  set(CMAKE_POSITION_INDEPENDENT_CODE ON)
  message(STATUS "vrelab: the Python module for ${Python_EXECUTABLE} (${Python_VERSION}), pybind11 ${pybind11_VERSION}")
else()
  message(STATUS "vrelab: no Python module (needs pybind11-dev and python3-dev; -DVRELAB_PYTHON=OFF silences this)")
endif()
