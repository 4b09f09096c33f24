#!/usr/bin/env bash
# Installs an animat build into a temporary prefix, then configures, builds and runs the downstream
# project of this folder against that installation (find_package(animat CONFIG REQUIRED)). The project
# sets no C++ standard: it builds only if the installed targets require C++20 themselves.
#
#   examples/downstream/build_against_install.sh BUILD_DIR [WORK_DIR]
#
# BUILD_DIR is a configured and built animat build tree; WORK_DIR (default: a fresh temporary folder,
# removed afterwards) receives prefix/ and build/. CMAKE (default: cmake on PATH) and CXX choose the
# tools. Exits 77 (ctest: skipped) only when there is no cmake.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:?usage: $0 BUILD_DIR [WORK_DIR]}" && pwd)
cmake=${CMAKE:-cmake}
if ! command -v "$cmake" >/dev/null 2>&1; then
  echo "SKIP: no cmake ($cmake) to build the downstream project with"
  exit 77
fi
if [[ -n ${2:-} ]]; then
  work=$2
  rm -rf "$work/prefix" "$work/build"
  mkdir -p "$work"
else
  work=$(mktemp -d "${TMPDIR:-/tmp}/animat-downstream.XXXXXX")
  trap 'rm -rf "$work"' EXIT
fi
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)

"$cmake" --install "$build" --prefix "$work/prefix" >/dev/null
# The project sets no C++ standard: the package must require C++20 itself. Checked in the exported
# targets too, since a compiler whose default is C++20 would build the project without it.
targets=$(find "$work/prefix" -name animatTargets.cmake)
if ! grep -q 'INTERFACE_COMPILE_FEATURES "cxx_std_20"' "$targets"; then
  echo "FAIL: $targets: the exported targets do not require cxx_std_20 (INTERFACE_COMPILE_FEATURES)" >&2
  exit 1
fi
"$cmake" -S "$here" -B "$work/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" ${CXX:+-DCMAKE_CXX_COMPILER="$CXX"} >/dev/null
if ! "$cmake" --build "$work/build" -j 2 >"$work/build.log" 2>&1; then
  cat "$work/build.log" >&2
  echo "FAIL: the downstream project did not build against the installed package (above)" >&2
  exit 1
fi
"$work/build/swim_random"
