# Loaded after CMake's Darwin platform rules (CMAKE_USER_MAKE_RULES_OVERRIDE in zig-macos.cmake):
# zig's Mach-O linker crashes (segmentation fault) on CMake's `-bundle -Wl,-headerpad_max_install_names`
# for a MODULE; a plain dylib (-shared), which Python's dlopen loads as well, links.
set(CMAKE_SHARED_MODULE_CREATE_C_FLAGS "-shared")
set(CMAKE_SHARED_MODULE_CREATE_CXX_FLAGS "-shared")
