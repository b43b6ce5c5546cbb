"""The solver for macOS (arm64 and x86_64), cross-built on this Linux machine with zig's clang
(PyPI `ziglang`). UNTESTED: nothing made here has run on a Mac; the wheels it feeds
(scripts/wheels.py) are marked so.

    macos.py module aarch64|x86_64 3.11|3.13   builds _wiresculpt.cpython-3XX-darwin.so, prints its path

Kept under ~/.cache/wiresculpt/macos/ as scripts/windows.py keeps the Windows build: zig, its
cache, compiler wrappers, static GLPK and NLopt from Debian's sources (the same trees Windows
uses), the headers (a Linux Python's with cmake/macos-pyconfig.h as pyconfig.h, not checked
against a real interpreter), and the modules by a hash of the native sources. The module links
with `-undefined dynamic_lookup` (Python's symbols come from the interpreter that loads it),
libc++ static; macos.dylibs() reads its load commands (llvm-objdump) and module() refuses one
that needs anything but the system's libSystem. Serial ports through the termios back end
(WIRESCULPT_SERIAL_BACKEND=posix, native/src/fab/serial_posix.cpp: libserialport's source is not
here); it is tested on Linux's ptys (ctest posix-backend/...), not on a Mac.
"""
import glob
import hashlib
import os
import shutil
import subprocess
import sys

import windows

ROOT = windows.ROOT
CACHE = os.path.join(os.path.dirname(windows.CACHE), "macos")
TOOLCHAIN = os.path.join(ROOT, "cmake", "zig-macos.cmake")
PYCONFIG = os.path.join(ROOT, "cmake", "macos-pyconfig.h")
ZIG = "0.17.1"
ARCHS = ("aarch64", "x86_64")
MINOS = "11.0"  # the oldest macOS Blender 4.2+ runs on
WHEEL_TAG = {"aarch64": "macosx_11_0_arm64", "x86_64": "macosx_11_0_x86_64"}
SYSTEM = ("/usr/lib/libSystem.B.dylib",)
BUILD_KEY = "2"  # 2: serial ports through the posix back end


def zig_bin():
    """A folder of wrappers <arch>-macos-{cc,c++,ar,ranlib} around zig."""
    site = os.path.join(CACHE, f"zig-{ZIG}")
    if not os.path.isfile(os.path.join(site, ".complete")):
        shutil.rmtree(site, ignore_errors=True)
        windows.pip("install", "-q", "--root-user-action=ignore", "--no-deps", "--target", site, f"ziglang=={ZIG}")
        open(os.path.join(site, ".complete"), "w").close()
    folder = os.path.join(CACHE, "bin")
    os.makedirs(folder, exist_ok=True)
    for arch in ARCHS:
        for tool, zig_tool in (("cc", "cc"), ("c++", "c++"), ("ar", "ar"), ("ranlib", "ranlib")):
            target = [] if tool in ("ar", "ranlib") else ["-target", f"{arch}-macos.{MINOS}"]
            path = os.path.join(folder, f"{arch}-macos-{tool}")
            with open(path, "w") as f:
                f.write("#!/bin/sh\n"
                        f"export ZIG_GLOBAL_CACHE_DIR='{os.path.join(CACHE, 'zigcache')}'\n"
                        f"PYTHONPATH='{site}' exec {windows.HOST_PYTHON} -m ziglang {zig_tool} {' '.join(target)} \"$@\"\n")
            os.chmod(path, 0o755)
    return folder


def deps(arch):
    trees = windows.fetch_sources(os.path.join(windows.CACHE, "src"))
    key = "-".join(os.path.basename(trees[n]) for n in windows.SOURCES)
    prefix = os.path.join(CACHE, f"deps-{arch}-{key}")
    if os.path.isfile(os.path.join(prefix, ".complete")):
        return prefix
    bin_ = zig_bin()
    shutil.rmtree(prefix, ignore_errors=True)
    build = os.path.join(CACHE, f"deps-build-{arch}")
    shutil.rmtree(build, ignore_errors=True)
    os.makedirs(build)
    log = os.path.join(CACHE, f"deps-{arch}.log")
    open(log, "w").close()
    windows.say(f"building static GLPK and NLopt for macOS {arch} into {prefix}")
    glpk = os.path.join(build, "glpk")
    shutil.copytree(trees["glpk"], glpk)
    windows.run(["./configure", f"--host={arch}-apple-darwin", f"--prefix={prefix}", "--disable-shared",
                 "--enable-static", f"CC={bin_}/{arch}-macos-cc", f"AR={bin_}/{arch}-macos-ar",
                 f"RANLIB={bin_}/{arch}-macos-ranlib", "CFLAGS=-O2"], log=log, cwd=glpk)
    windows.run(["make", f"-j{windows.jobs()}", "-C", "src"], log=log, cwd=glpk)
    os.makedirs(os.path.join(prefix, "lib"), exist_ok=True)
    os.makedirs(os.path.join(prefix, "include"), exist_ok=True)
    shutil.copy2(os.path.join(glpk, "src", ".libs", "libglpk.a"), os.path.join(prefix, "lib"))
    shutil.copy2(os.path.join(glpk, "src", "glpk.h"), os.path.join(prefix, "include"))
    env = dict(os.environ, CMAKE_POLICY_VERSION_MINIMUM="3.5")
    nlopt = os.path.join(build, "nlopt")
    windows.run([windows.CMAKE, "-S", trees["nlopt"], "-B", nlopt, f"-DCMAKE_TOOLCHAIN_FILE={TOOLCHAIN}",
                 f"-DWIRESCULPT_ZIG_BIN={bin_}", f"-DWIRESCULPT_ZIG_ARCH={arch}", "-DCMAKE_BUILD_TYPE=Release",
                 f"-DCMAKE_INSTALL_PREFIX={prefix}", "-DBUILD_SHARED_LIBS=OFF", "-DNLOPT_PYTHON=OFF",
                 "-DNLOPT_OCTAVE=OFF", "-DNLOPT_MATLAB=OFF", "-DNLOPT_GUILE=OFF", "-DNLOPT_SWIG=OFF",
                 "-DNLOPT_TESTS=OFF", "-DNLOPT_FORTRAN=OFF"], log=log, env=env)
    windows.run([windows.CMAKE, "--build", nlopt, f"-j{windows.jobs()}"], log=log, env=env)
    windows.run([windows.CMAKE, "--install", nlopt], log=log, env=env)
    shutil.rmtree(build, ignore_errors=True)
    open(os.path.join(prefix, ".complete"), "w").close()
    return prefix


def headers(minor):
    """The macOS headers of `minor`: a Linux header tree with cmake/macos-pyconfig.h as its pyconfig.h."""
    return windows.headers(minor, PYCONFIG, CACHE)


def dylibs(path):
    """The dylibs a Mach-O file loads (llvm-objdump --macho --dylibs-used)."""
    out = subprocess.run(["llvm-objdump", "--macho", "--dylibs-used", path], capture_output=True, text=True,
                         check=True).stdout
    own = os.path.basename(path)  # a dylib lists its own id first
    return [d for d in (line.split()[0] for line in out.splitlines()[1:] if line.strip())
            if os.path.basename(d) != own]


def kept_folder(arch, prefix):
    """Where the modules of this source tree for `arch` are kept (a hash of what they are made of)."""
    h = hashlib.sha256(windows.source_hash(prefix).encode() + BUILD_KEY.encode())
    for path in (TOOLCHAIN, PYCONFIG, os.path.join(ROOT, "cmake", "zig-macos-rules.cmake")):
        with open(path, "rb") as f:
            h.update(f.read())
    return os.path.join(CACHE, "modules", f"{arch}-{h.hexdigest()[:16]}")


def cached_module(arch, minor):
    """The module if this tree's is in the cache (nothing built or fetched), else None."""
    name = f"_wiresculpt.cpython-{minor.replace('.', '')}-darwin.so"
    for done in glob.glob(os.path.join(CACHE, f"deps-{arch}-*", ".complete")):
        path = os.path.join(kept_folder(arch, os.path.dirname(done)), name)
        if os.path.isfile(path):
            return path
    return None


def module(arch, minor):
    tag = "cp" + minor.replace(".", "")
    name = f"_wiresculpt.cpython-{tag[2:]}-darwin.so"
    prefix = deps(arch)
    kept = kept_folder(arch, prefix)
    if os.path.isfile(os.path.join(kept, name)):
        return os.path.join(kept, name)
    bin_ = zig_bin()
    folder = os.path.join(ROOT, "build", f"macos-{arch}", "py" + tag[2:])
    core_folder = os.path.join(ROOT, "build", f"macos-{arch}", "py311")
    out = os.path.join(folder, "module")
    os.makedirs(folder, exist_ok=True)
    log = os.path.join(folder, "build.log")
    open(log, "w").close()
    configure = [windows.CMAKE, "-S", ROOT, "-B", folder, f"-DCMAKE_TOOLCHAIN_FILE={TOOLCHAIN}",
                 f"-DWIRESCULPT_ZIG_BIN={bin_}", f"-DWIRESCULPT_ZIG_ARCH={arch}", "-DCMAKE_BUILD_TYPE=Release",
                 f"-DWIRESCULPT_DEPS_PREFIX={prefix}", f"-DNLopt_DIR={prefix}/lib/cmake/nlopt",
                 # named, not searched: a build folder keeps what find_library found for another prefix
                 f"-DGLPK_LIBRARY={prefix}/lib/libglpk.a", f"-DGLPK_INCLUDE_DIR={prefix}/include",
                 "-DEigen3_DIR=/usr/share/eigen3/cmake", "-DWIRESCULPT_SERIAL_PORT=ON", "-DWIRESCULPT_SERIAL_BACKEND=posix",
                 "-DWIRESCULPT_BUILD_TESTS=OFF",
                 f"-DWIRESCULPT_PYTHON_INCLUDE_DIR={headers(minor)}", "-DWIRESCULPT_PYTHON_LIBRARY=",
                 f"-DWIRESCULPT_PYBIND11_INCLUDE_DIR={windows.pybind11_include()}",
                 f"-DWIRESCULPT_MODULE_SUFFIX=.cpython-{tag[2:]}-darwin.so", f"-DWIRESCULPT_MODULE_DIR={out}"]
    if folder != core_folder:
        module(arch, "3.11")
        configure.append(f"-DWIRESCULPT_CORE_LIBRARY={os.path.join(core_folder, 'native', 'libwiresculpt_core.a')}")
    windows.say(f"building the solver for macOS {arch}, Python {minor} (untested; log: {log})")
    windows.run(configure, log=log)
    windows.run([windows.CMAKE, "--build", folder, "--target", "_wiresculpt", f"-j{windows.jobs()}"], log=log)
    built = os.path.join(out, name)
    stray = [d for d in dylibs(built) if d not in SYSTEM]
    if stray:
        raise SystemExit(f"wiresculpt: {name} for macOS {arch} loads {', '.join(stray)}, not only the system's")
    os.makedirs(kept, exist_ok=True)
    shutil.copy2(built, os.path.join(kept, name))
    return os.path.join(kept, name)


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "module":
        print(module(sys.argv[2], sys.argv[3]))
    else:
        raise SystemExit(__doc__)
