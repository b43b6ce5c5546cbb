#pragma once
// GLPK without aborts or terminal output, shared by every stage that solves LPs (stability,
// forces, load capacity). Private to the core; only lp.cpp includes it.
//
// GLPK reports internal errors (an invalid scale factor, an index out of range, a numerical
// failure it cannot recover from) through a hook and aborts the process if the hook returns. GLPK's
// manual (glp_error_hook): the hook may leave with longjmp, and the program must then call
// glp_free_env, which frees every problem object of the (per-thread) environment. run_guarded
// does exactly that: every GLPK call of the core runs inside a body it calls, the hook jumps back
// to it, it frees the environment and counts a new generation, which glpk_generation() tells
// holders of problem objects (theirs are gone; never touch or delete them again).
//
// Only the body's frames and GLPK's own C frames lie between setjmp and longjmp, so a body holds
// only trivially destructible locals and calls nothing that throws (longjmp over a frame with a
// destructor is undefined behaviour in C++).
#include <glpk.h>

namespace wiresculpt::detail {

/// Increases each time GLPK's environment was freed after an internal error on this thread.
unsigned glpk_generation();

/// Frees this thread's GLPK environment (every problem object in it; glpk_generation() increases).
/// GLPK does not free it when a thread ends: a thread that solved LPs calls this before it ends.
void free_glpk_environment();

/// Turns GLPK's terminal output off for the current environment (the core never prints).
void configure_glpk();

/// Runs body(context) with GLPK's error hook unwinding here. True when the body returned; false
/// when GLPK hit an internal error inside it (its environment, with every problem object in it,
/// is then freed and glpk_generation() has increased). Not reentrant: a body does not call it.
bool run_guarded(void (*body)(void*), void* context);

}  // namespace wiresculpt::detail
