#pragma once
// GLPK without aborts or terminal output, shared by every stage that solves LPs (stability,
// forces, load capacity). Private to the core.
//
// GLPK reports internal errors through a hook and aborts the process if the hook returns. The
// hook jumps back to guarded_simplex, which frees GLPK's (per-thread) environment as GLPK
// requires; every problem object of that environment is then gone, which glpk_generation()
// tells holders of problem objects. Only GLPK's own C frames lie between setjmp and longjmp.
#include <glpk.h>

namespace wiresculpt::detail {

/// Increases each time GLPK's environment was freed after an internal error on this thread.
unsigned glpk_generation();

/// Turns GLPK's terminal output off for the current environment (the core never prints).
void configure_glpk();

/// glp_simplex with GLPK's error hook unwinding here: its return code, or -1 when GLPK hit an
/// internal error (its environment, with every problem object in it, is then freed).
int guarded_simplex(glp_prob* lp, const glp_smcp* parm);

}  // namespace wiresculpt::detail
