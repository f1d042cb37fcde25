#!/usr/bin/env bash
# The installed package, as a user gets it: installs the build tree into a temporary prefix,
# builds and runs the consumer (tests/consumer) against it with find_package(vrelab), then
# moves the prefix and runs the installed program there on a small frequency study, which
# must draw its figure with the plot scripts of the prefix (share/vrelab/plots).
# Usage: check.sh CMAKE BUILD_DIR CXX_COMPILER BUILD_TYPE [COMPILER_LAUNCHER]
set -euo pipefail
cmake_exe=$1 build_dir=$2 cxx=$3 build_type=$4 launcher=${5:-}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/vrelab-package.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
log=$tmp/log
step() { echo "== $*"; }
quiet() { "$@" >"$log" 2>&1 || { cat "$log"; echo "FAILED: $*"; exit 1; }; }

step "cmake --install $build_dir --prefix $tmp/prefix"
quiet "$cmake_exe" --install "$build_dir" --prefix "$tmp/prefix"
for f in bin/vrelab lib/cmake/vrelab/vrelabConfig.cmake lib/cmake/vrelab/vrelabConfigVersion.cmake \
         include/vrelab/vrelab_version.hpp include/vrelab/rectification/simulation/shake.hpp \
         share/vrelab/plots/frequency.py share/vrelab/plots/reproduce.py; do
  [ -e "$tmp/prefix/$f" ] || { echo "FAILED: $f is not installed"; exit 1; }
done

step "consumer: find_package(vrelab) against the prefix"
launcher_arg=()
[ -n "$launcher" ] && launcher_arg=("-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher")
quiet "$cmake_exe" -S "$here" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_CXX_COMPILER="$cxx" \
  -DCMAKE_BUILD_TYPE="$build_type" "${launcher_arg[@]}"
quiet "$cmake_exe" --build "$tmp/consumer"
"$tmp/consumer/vrelab_consumer"

step "the installed program, the prefix moved, finds its plot scripts"
mv "$tmp/prefix" "$tmp/moved"
if ! /usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1 && ! python3 -c 'import matplotlib' >/dev/null 2>&1; then
  echo "FAILED: no Python with matplotlib (apt-get install python3-matplotlib; setup.sh installs it)"
  exit 1
fi
env -u VRELAB_PLOTS_DIR "$tmp/moved/bin/vrelab" frequency "$here/frequency-small.toml" --out "$tmp/out" | tee "$log"
[ -s "$tmp/out/frequency.png" ] || { echo "FAILED: no $tmp/out/frequency.png"; exit 1; }
echo "package: ok ($tmp/out/frequency.png drawn by the installed program)"
