#include "glpk_guard.hpp"

#include <csetjmp>

namespace wiresculpt::detail {
namespace {

thread_local std::jmp_buf* t_jump = nullptr;
thread_local unsigned t_generation = 0;
thread_local unsigned t_configured = ~0u;

void on_glpk_error(void*) {
  if (t_jump) std::longjmp(*t_jump, 1);
  // No guard is active: every GLPK call of the core runs inside run_guarded, so this is not
  // reached; returning would let GLPK abort.
}

// GLPK prints its error messages even with terminal output off (it turns it on to report an
// error); a terminal hook that claims every line keeps the core silent.
int swallow_output(void*, const char*) { return 1; }

}  // namespace

unsigned glpk_generation() { return t_generation; }

void free_glpk_environment() {
  glp_free_env();
  ++t_generation;
}

void configure_glpk() {
  if (t_configured == t_generation) return;
  glp_term_out(GLP_OFF);
  glp_term_hook(swallow_output, nullptr);
  t_configured = t_generation;
}

bool run_guarded(void (*body)(void*), void* context) {
  configure_glpk();
  std::jmp_buf buf;
  t_jump = &buf;
  glp_error_hook(on_glpk_error, nullptr);
  if (setjmp(buf) != 0) {
    // GLPK's manual: after leaving the hook by longjmp, free the environment (it is in an
    // undefined state); this frees every problem object created in it.
    t_jump = nullptr;
    glp_free_env();
    ++t_generation;
    return false;
  }
  body(context);
  glp_error_hook(nullptr, nullptr);
  t_jump = nullptr;
  return true;
}

}  // namespace wiresculpt::detail
