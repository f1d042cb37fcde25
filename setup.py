"""Builds the extension vrelab._core with the project's CMake (pyproject.toml; docs/python.md).

The library and the module are compiled in Release by CMake for the interpreter running pip
(-DPython_EXECUTABLE), in build-python/<interpreter tag>/ under the source tree, so a second
`pip install` rebuilds only what changed. VRELAB_BUILD_DIR names an existing build folder
instead (e.g. setup.sh's build/): its module is taken as that build made it (nothing is
compiled; build it first), after checking that it was built for this interpreter.
CMAKE_ARGS adds CMake options; VRELAB_BUILD_JOBS the parallel jobs (default: all cores).
The plot scripts (tools/plots) are installed as vrelab/plots.
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


def project_version():
    with open(os.path.join(HERE, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(vrelab VERSION ([0-9.]+)", f.read())
    if not m:
        sys.exit("setup.py: CMakeLists.txt: no 'project(vrelab VERSION x.y.z' line")
    return m.group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        given = os.environ.get("VRELAB_BUILD_DIR")
        if given:  # the module as that build made it: nothing is compiled here
            build_dir = os.path.abspath(given)
            if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
                sys.exit("setup.py: VRELAB_BUILD_DIR=%s is not a configured CMake build folder" % build_dir)
        else:
            build_dir = os.path.join(HERE, "build-python", sys.implementation.cache_tag)
            generator = ["-G", "Ninja"] if shutil.which("ninja") and not os.path.isfile(
                os.path.join(build_dir, "CMakeCache.txt")) else []
            self._cmake(["cmake", "-S", HERE, "-B", build_dir, *generator, "-DCMAKE_BUILD_TYPE=Release",
                      "-DVRELAB_TESTS=OFF", "-DVRELAB_BENCH=OFF", "-DVRELAB_PYTHON=ON",
                      "-DPython_EXECUTABLE=" + sys.executable, *os.environ.get("CMAKE_ARGS", "").split()])
            jobs = os.environ.get("VRELAB_BUILD_JOBS", str(os.cpu_count() or 1))
            self._cmake(["cmake", "--build", build_dir, "--target", "vrelab_python", "-j", jobs])
        built = os.path.join(build_dir, "python", "vrelab", "_core" + suffix)
        if not os.path.isfile(built):
            found = glob.glob(os.path.join(build_dir, "python", "vrelab", "_core*"))
            sys.exit("setup.py: %s has no module for this interpreter (%s wants _core%s; found %s): "
                     "build it for %s, or leave VRELAB_BUILD_DIR unset"
                     % (build_dir, sys.executable, suffix, ", ".join(map(os.path.basename, found)) or "none",
                        sys.executable))
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)

    @staticmethod
    def _cmake(cmd):
        print("setup.py:", " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)


os.makedirs(os.path.join(HERE, "build-python"), exist_ok=True)  # egg_base below
setup(
    version=project_version(),
    packages=["vrelab", "vrelab.plots"],
    package_dir={"vrelab": "python/vrelab", "vrelab.plots": "tools/plots"},
    ext_modules=[Extension("vrelab._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # setuptools' own scratch folder apart from CMake's build/ (setup.sh's).
    options={"build": {"build_base": "build-python/setuptools"}, "egg_info": {"egg_base": "build-python"}},
    zip_safe=False,
)
