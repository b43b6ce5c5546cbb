# Cross-building for Windows x64 (win_amd64) on Debian with MinGW-w64 GCC, the posix-threads
# variant (std::thread): scripts/windows.py configures with
#   -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64-x86_64.cmake -DWIRESCULPT_DEPS_PREFIX=<static GLPK, NLopt>
# and the Windows Python's headers, DLL and suffix (native/CMakeLists.txt, WIRESCULPT_PYTHON_INCLUDE_DIR).
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR AMD64)
set(CMAKE_C_COMPILER x86_64-w64-mingw32-gcc-posix)
set(CMAKE_CXX_COMPILER x86_64-w64-mingw32-g++-posix)
set(CMAKE_RC_COMPILER x86_64-w64-mingw32-windres)
set(CMAKE_AR x86_64-w64-mingw32-ar CACHE FILEPATH "")
set(CMAKE_RANLIB x86_64-w64-mingw32-ranlib CACHE FILEPATH "")

set(WIRESCULPT_DEPS_PREFIX "" CACHE PATH "Where the static Windows GLPK and NLopt are installed")
set(CMAKE_FIND_ROOT_PATH /usr/x86_64-w64-mingw32 ${WIRESCULPT_DEPS_PREFIX})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(CMAKE_FIND_LIBRARY_SUFFIXES .a)  # static GLPK and NLopt, never an import library

# Everything of GCC's runtime inside the module (libstdc++, libgcc, winpthreads): -static-libgcc
# -static-libstdc++ alone still imports libwinpthread-1.dll. Big objects: the bindings have more
# sections than PE/COFF's default allows.
set(CMAKE_CXX_FLAGS_INIT "-Wa,-mbig-obj")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-static -s")
set(CMAKE_MODULE_LINKER_FLAGS_INIT "-static -s")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
