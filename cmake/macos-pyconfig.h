/* pyconfig.h for building extension modules of python.org's (or Blender's) macOS CPython 3.11-3.13,
 * arm64 or x86_64, with zig's clang on Linux (scripts/macos.py puts it in place of pyconfig.h in a
 * copy of a Linux Python's headers). Only what the public headers an extension includes test for:
 * LP64 sizes and the headers the C library has. Written for wiresculpt and NOT checked against a
 * real interpreter: nothing built with it has run on a Mac. */
#ifndef Py_PYCONFIG_H
#define Py_PYCONFIG_H

#if !defined(__APPLE__) || !defined(__LP64__)
#error "this pyconfig.h is for 64-bit macOS targets only"
#endif

#define SIZEOF_SHORT 2
#define SIZEOF_INT 4
#define SIZEOF_LONG 8
#define ALIGNOF_LONG 8
#define SIZEOF_LONG_LONG 8
#define SIZEOF_LONG_DOUBLE 16
#define SIZEOF_DOUBLE 8
#define SIZEOF_FLOAT 4
#define SIZEOF_VOID_P 8
#define SIZEOF_SIZE_T 8
#define ALIGNOF_SIZE_T 8
#define SIZEOF_TIME_T 8
#define SIZEOF_OFF_T 8
#define SIZEOF_FPOS_T 8
#define SIZEOF_PID_T 4
#define SIZEOF_PTHREAD_T 8
#define SIZEOF_PTHREAD_KEY_T 8
#define SIZEOF_WCHAR_T 4
#define SIZEOF__BOOL 1
#define SIZEOF_UINTPTR_T 8
#define HAVE_UINTPTR_T 1
#define HAVE_INTPTR_T 1
#define HAVE_SSIZE_T 1
#define HAVE_LONG_DOUBLE 1
#define DOUBLE_IS_LITTLE_ENDIAN_IEEE754 1

#define STDC_HEADERS 1
#define HAVE_UNISTD_H 1
#define HAVE_STDDEF_H 1
#define HAVE_STDINT_H 1
#define HAVE_INTTYPES_H 1
#define HAVE_SYS_TYPES_H 1
#define HAVE_SYS_STAT_H 1
#define HAVE_SYS_TIME_H 1
#define HAVE_SYS_SELECT_H 1
#define HAVE_ERRNO_H 1
#define HAVE_FCNTL_H 1
#define HAVE_SIGNAL_H 1
#define HAVE_WCHAR_H 1
#define HAVE_PTHREAD_H 1
#define HAVE_CLOCK_GETTIME 1
#define HAVE_DYNAMIC_LOADING 1
#define HAVE_STD_ATOMIC 1
#define HAVE_BUILTIN_ATOMIC 1

#define WITH_PYMALLOC 1
#define WITH_DOC_STRINGS 1
#define WITH_FREELISTS 1
#define WITH_DECIMAL_CONTEXTVAR 1
#define Py_ENABLE_SHARED 1
#define WITH_NEXT_FRAMEWORK 1

#endif /* Py_PYCONFIG_H */
