# Cross-building for macOS (arm64 or x86_64) on Linux with zig's clang (PyPI `ziglang`):
# scripts/macos.py writes compiler wrappers (`python -m ziglang cc -target <arch>-macos.11.0`) and
# configures with -DCMAKE_TOOLCHAIN_FILE=cmake/zig-macos.cmake -DWIRESCULPT_ZIG_BIN=<wrappers>
# -DWIRESCULPT_ZIG_ARCH=aarch64|x86_64. Untested: nothing made with it has run on a Mac.
set(CMAKE_SYSTEM_NAME Darwin)
set(CMAKE_SYSTEM_PROCESSOR ${WIRESCULPT_ZIG_ARCH})
set(CMAKE_C_COMPILER ${WIRESCULPT_ZIG_BIN}/${WIRESCULPT_ZIG_ARCH}-macos-cc)
set(CMAKE_CXX_COMPILER ${WIRESCULPT_ZIG_BIN}/${WIRESCULPT_ZIG_ARCH}-macos-c++)
set(CMAKE_AR ${WIRESCULPT_ZIG_BIN}/${WIRESCULPT_ZIG_ARCH}-macos-ar CACHE FILEPATH "")
set(CMAKE_RANLIB ${WIRESCULPT_ZIG_BIN}/${WIRESCULPT_ZIG_ARCH}-macos-ranlib CACHE FILEPATH "")
set(CMAKE_OSX_SYSROOT "" CACHE PATH "")
set(CMAKE_OSX_DEPLOYMENT_TARGET "" CACHE STRING "")

set(WIRESCULPT_DEPS_PREFIX "" CACHE PATH "Where the static macOS GLPK and NLopt are installed")
set(CMAKE_FIND_ROOT_PATH ${WIRESCULPT_DEPS_PREFIX})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(CMAKE_FIND_LIBRARY_SUFFIXES .a)

# The module resolves Python's symbols from the interpreter that loads it.
set(CMAKE_MODULE_LINKER_FLAGS_INIT "-Wl,-undefined,dynamic_lookup")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-Wl,-undefined,dynamic_lookup")

set(CMAKE_USER_MAKE_RULES_OVERRIDE ${CMAKE_CURRENT_LIST_DIR}/zig-macos-rules.cmake)
