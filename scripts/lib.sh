# Shared by the scripts: paths, package installation and the build. Source it, don't run it.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${WIRESCULPT_BUILD_DIR:-$ROOT/build/release}
# Blender 3.4 from Debian embeds Debian's Python 3.11; another python3 may come first on PATH.
PYTHON=/usr/bin/python3.11
BLENDER=${BLENDER:-blender}
# Debian's CMake and the pybind11 it packages: a pip-installed cmake (4.x) or pybind11 may come
# first on PATH, and neither matches the Debian libraries the build links.
CMAKE=/usr/bin/cmake
CTEST=/usr/bin/ctest
PYBIND11_DIR=/usr/lib/cmake/pybind11

# Debian packages the build, the tests and the demo need.
PACKAGES=(
  cmake g++ make pkg-config
  blender python3.11 python3-dev python3-numpy
  libeigen3-dev pybind11-dev catch2
  libglpk-dev libnlopt-cxx-dev libserialport-dev
  patchelf binutils  # scripts/package bundles the solver's libraries with an $ORIGIN run path
)

# Blender as a Python module (PyPI `bpy`), one venv per pinned version under BPY_CACHE, reused when
# present: 4.5 LTS (supported to July 2027), 5.0 (the newest bpy built for Python 3.11) and 5.3 (the
# newest, Python 3.13; our module for 3.13 is built as scripts/package builds it). 4.2 LTS left
# support in July 2026 and is no longer run. scripts/test runs the Blender suites against each.
BPY_VERSIONS=(4.5.15 5.0.1 5.3.0)
# The Python each is built for (its wheel's cp tag) and what it runs with: bpy 4.5 and 5.0 require
# numpy < 2 (1.26.4, what Blender bundles); bpy 5.1+ requires numpy >= 2.2, which the 3.13 module
# (pybind11 2.13) supports. The independent re-check (blender_tests/pure/recheck.py) that the
# plane-assistant suites run needs scipy: a release built for that numpy and Python.
declare -A BPY_PYTHON=([4.5.15]=3.11 [5.0.1]=3.11 [5.3.0]=3.13)
declare -A BPY_NUMPY=([3.11]=1.26.4 [3.13]=2.2.6)
declare -A BPY_SCIPY=([3.11]=1.13.1 [3.13]=1.15.3)
BPY_CACHE=${WIRESCULPT_BPY_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/wiresculpt}

# scripts/package builds the module for every further CPython 3.x on the machine (package_pythons.py)
# with this pybind11: Debian's 2.10 predates Python 3.12 and 3.13. 2.13.6 is the last 2.x (the API
# our bindings are written for) and supports Python 3.7 to 3.13; its wheel is the same for every
# Python (headers and CMake files), so one copy serves them all.
PACKAGE_PYBIND11=2.13.6

# The Windows build and its tests (scripts/windows.py, scripts/test_windows): MinGW-w64 GCC with
# posix threads (std::thread) and Wine (64-bit only; bookworm's wine64 has no wine64 on PATH).
WINDOWS_PACKAGES=(g++-mingw-w64-x86-64-posix gcc-mingw-w64-x86-64-posix wine64 python3-pip)

# The sanitizer and fuzz builds (scripts/test, scripts/fuzz).
FUZZ_PACKAGES=(clang libclang-rt-14-dev)

# The benchmark's plot (scripts/bench).
BENCH_PACKAGES=(python3-matplotlib)

say() { printf 'wiresculpt: %s\n' "$*" >&2; }

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

# Installs whichever of the named Debian packages are missing; does nothing when all are there.
ensure_packages() {
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  say "installing ${missing[*]}"
  as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# Configures (once) and builds the library, the Python module and the tests.
build() {
  if [ ! -f "$BUILD_DIR/Makefile" ]; then  # a failed configure leaves a cache but no Makefile
    "$CMAKE" -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE="$PYTHON" \
      -Dpybind11_DIR="$PYBIND11_DIR" >/dev/null
  fi
  if ! "$CMAKE" --build "$BUILD_DIR" -j"$(nproc)" >"$BUILD_DIR/build.log" 2>&1; then
    cat "$BUILD_DIR/build.log" >&2
    say "build failed (log: $BUILD_DIR/build.log)"
    return 1
  fi
  grep -E 'warning:' "$BUILD_DIR/build.log" | grep -v 'lto-wrapper' >&2 || true
}

# The native tests built with AddressSanitizer and UBSan (no Python module).
build_sanitize() {
  if [ ! -f "$ROOT/build/sanitize/Makefile" ]; then
    "$CMAKE" --preset sanitize -S "$ROOT" >/dev/null
  fi
  "$CMAKE" --build "$ROOT/build/sanitize" -j"$(nproc)" >"$ROOT/build/sanitize/build.log" 2>&1 ||
    { cat "$ROOT/build/sanitize/build.log" >&2; say "sanitizer build failed"; return 1; }
}

# The libFuzzer targets, built with clang.
build_fuzz() {
  if [ ! -f "$ROOT/build/fuzz/Makefile" ]; then
    "$CMAKE" --preset fuzz -S "$ROOT" >/dev/null
  fi
  "$CMAKE" --build "$ROOT/build/fuzz" -j"$(nproc)" >"$ROOT/build/fuzz/build.log" 2>&1 ||
    { cat "$ROOT/build/fuzz/build.log" >&2; say "fuzz build failed"; return 1; }
}

# The demo's closing lines: every file and folder a batch run wrote into $1 (exit status $2), one
# line each with what it holds.
summarize_outputs() {
  local out=$1 code=${2:-0} entry name what
  say "done: the results are in $out/"
  for entry in "$out"/*; do
    [ -e "$entry" ] || continue
    name=$(basename "$entry")
    case "$name" in
      design.json) what="the design: wires, crossings, stability, assembly order" ;;
      sculpture.blend) what="open in Blender: framed on the sculpture, sidebar on the Wire tab, first wire selected" ;;
      sculpture.blend1) what="the previous sculpture.blend (Blender's backup)" ;;
      render.png) what="a still of the wire sculpture" ;;
      assembly) what="the printable assembly guide (index.html), one picture per step" ;;
      svg) what="machine files: each wire's rest shape as one path, in mm, from its start" ;;
      dxf) what="machine files: DXF R2000 in mm per wire, and sculpture.dxf with every wire side by side" ;;
      templates) what="print templates at 1:1 (bends, crossings, labels); sheet.svg holds them all" ;;
      gcode) what="bend programs for a GRBL wire bender (or send them from the Fabrication panel)" ;;
      bends) what="bend tables (CSV): feed, bend angle and commanded angle per step" ;;
      bendlist) what="bend lists (UNIT/FEED/BEND) for a DIWire-class machine through FabMo's Bend List app" ;;
      *) what="" ;;
    esac
    [ -d "$entry" ] && name="$name/"
    say "$(printf '  %-20s %s' "$name" "$what")"
  done
  [ "$code" -eq 2 ] && say "  not stable: see \"reason\" in design.json or the Stability panel" || true
}

# Prints an interpreter of CPython $1 ("3.13"): the system's, else pyenv's newest $1.x; fails with
# a line saying so when there is none.
python_of() {
  local want=$1 p
  [ "$want" = "3.11" ] && { echo "$PYTHON"; return; }
  for p in "/usr/bin/python$want" "/usr/local/bin/python$want" \
           $(ls -d "${PYENV_ROOT:-$HOME/.pyenv}/versions/$want".* 2>/dev/null | sort -V -r | sed 's|$|/bin/python3|'); do
    [ -x "$p" ] && { echo "$p"; return; }
  done
  say "no Python $want on this machine (install it, e.g. with pyenv)"
  return 1
}

# Prints the python of a venv holding bpy==$1 (made with the Python that bpy is built for,
# BPY_PYTHON), making it once (a ~350 MB download; the wheel is kept in $BPY_CACHE/wheels); a
# venv is used only after its install finished. .complete holds the requirements it was made
# with; a venv made with fewer (an older checkout) gets the missing ones installed.
bpy_python() {
  local version=$1 venv="$BPY_CACHE/bpy-$1" minor=${BPY_PYTHON[$1]:-3.11} python
  local want=("bpy==$version" "numpy==${BPY_NUMPY[$minor]}" "scipy==${BPY_SCIPY[$minor]}")
  if [ -f "$venv/.complete" ] && [ "$(cat "$venv/.complete")" = "${want[*]}" ]; then
    echo "$venv/bin/python"
    return
  fi
  python=$(python_of "$minor") || return 1
  [ "$minor" = "3.11" ] && ensure_packages python3.11-venv
  if [ ! -f "$venv/.complete" ]; then
    rm -rf "$venv"
    mkdir -p "$BPY_CACHE/wheels"
    say "installing bpy $version into $venv"
    "$python" -m venv "$venv" >&2
    "$venv/bin/python" -m pip download -q --no-deps -d "$BPY_CACHE/wheels" "bpy==$version" >&2
  fi
  "$venv/bin/python" -m pip install -q --find-links "$BPY_CACHE/wheels" "${want[@]}" >&2
  echo "${want[*]}" >"$venv/.complete"
  echo "$venv/bin/python"
}

# Prints the folder holding pybind11Config.cmake of pybind11==$PACKAGE_PYBIND11, pip-installed once
# into $BPY_CACHE (never into a site-packages: --target); a copy is used only after its install
# finished.
package_pybind11() {
  local dir="$BPY_CACHE/pybind11-$PACKAGE_PYBIND11"
  if [ ! -f "$dir/.complete" ]; then
    ensure_packages python3-pip
    rm -rf "$dir"
    say "installing pybind11 $PACKAGE_PYBIND11 into $dir"
    "$PYTHON" -m pip install -q --root-user-action=ignore --no-deps --no-compile --target "$dir" "pybind11==$PACKAGE_PYBIND11" >&2
    touch "$dir/.complete"
  fi
  echo "$dir/pybind11/share/cmake/pybind11"
}

# Runs a Python file inside headless Blender; extra arguments follow "--".
blender_run() {
  local file=$1; shift
  "$BLENDER" --background --factory-startup --python-exit-code 1 --python "$file" -- "$@"
}
