/* pyconfig.h for building extension modules of python.org's Windows x64 CPython 3.11-3.13 with
 * MinGW-w64 on Linux (scripts/windows.py copies a Linux Python's headers and puts this file in the
 * copy's place of pyconfig.h: Python.h includes "pyconfig.h" from its own folder first).
 *
 * Only what the public headers an extension includes test for: the platform, the DLL linkage of
 * the API, and the sizes of the LLP64 types (long is 4 bytes, pointers 8, wchar_t 2). Written for
 * wiresculpt, checked by blender_tests/windows (the interpreter's own struct sizes against ours).
 * Not for the free-threaded builds (3.13t): Py_GIL_DISABLED is never defined here. */
#ifndef Py_CONFIG_H
#define Py_CONFIG_H

#if !defined(_WIN64) || !defined(__x86_64__)
#error "this pyconfig.h is for 64-bit x86 Windows targets (x86_64-w64-mingw32) only"
#endif

/* the platform */
#define MS_WIN32
#define MS_WIN64
#define MS_WINDOWS
#define NT_THREADS
#define WITH_THREAD
#define PLATFORM "win32"
#define PYD_PLATFORM_TAG "win_amd64"
#define COMPILER "[gcc]"
#define Py_WINVER 0x0602
#define Py_NTDDI NTDDI_WIN8

/* the API lives in pythonXY.dll: PyAPI_FUNC is dllimport, PyMODINIT_FUNC dllexport */
#define Py_ENABLE_SHARED 1
#define MS_COREDLL
#define HAVE_DECLSPEC_DLL

/* LLP64 */
typedef long long Py_ssize_t;
#define PY_SSIZE_T_MAX LLONG_MAX
#define HAVE_PY_SSIZE_T 1
#define SIZEOF_SHORT 2
#define SIZEOF_INT 4
#define SIZEOF_LONG 4
#define ALIGNOF_LONG 4
#define SIZEOF_LONG_LONG 8
#define SIZEOF_DOUBLE 8
#define SIZEOF_FLOAT 4
#define SIZEOF_VOID_P 8
#define SIZEOF_SIZE_T 8
#define ALIGNOF_SIZE_T 8
#define SIZEOF_TIME_T 8
#define SIZEOF_OFF_T 4
#define SIZEOF_FPOS_T 8
#define SIZEOF_HKEY 8
#define SIZEOF_WCHAR_T 2
#define SIZEOF__BOOL 1
#define SIZEOF_PID_T SIZEOF_INT
#define LONG_BIT 32
#define WORD_BIT 32
#define HAVE_LARGEFILE_SUPPORT
#define PY_LONG_LONG long long
#define PY_LLONG_MIN LLONG_MIN
#define PY_LLONG_MAX LLONG_MAX
#define PY_ULLONG_MAX ULLONG_MAX
#define PY_UINT32_T uint32_t
#define PY_UINT64_T uint64_t
#define PY_INT32_T int32_t
#define PY_INT64_T int64_t
#define HAVE_UINTPTR_T 1
#define HAVE_INTPTR_T 1
#define DOUBLE_IS_LITTLE_ENDIAN_IEEE754 1

/* headers the C library has */
#define STDC_HEADERS 1
#define HAVE_ERRNO_H 1
#define HAVE_FCNTL_H 1
#define HAVE_IO_H 1
#define HAVE_PROCESS_H 1
#define HAVE_SIGNAL_H 1
#define HAVE_STDDEF_H 1
#define HAVE_SYS_STAT_H 1
#define HAVE_SYS_TYPES_H 1
#define HAVE_WCHAR_H 1
#define HAVE_STDARG_PROTOTYPES
#define HAVE_PROTOTYPES
#define HAVE_DYNAMIC_LOADING
#define HAVE_STRERROR
#define HAVE_CLOCK
#define HAVE_ERF 1
#define HAVE_ERFC 1

/* how the interpreter was built (python.org's release builds) */
#define WITH_PYMALLOC 1
#define WITH_DOC_STRINGS 1
#define WITH_FREELISTS 1
#define WITH_DECIMAL_CONTEXTVAR 1

#endif /* Py_CONFIG_H */
