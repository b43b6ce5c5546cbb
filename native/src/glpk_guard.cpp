#include "glpk_guard.hpp"

#include <csetjmp>

namespace wiresculpt::detail {
namespace {

thread_local std::jmp_buf* t_jump = nullptr;
thread_local unsigned t_generation = 0;
thread_local unsigned t_configured = ~0u;

void on_glpk_error(void*) {
  if (t_jump) std::longjmp(*t_jump, 1);
}

}  // namespace

unsigned glpk_generation() { return t_generation; }

void configure_glpk() {
  if (t_configured == t_generation) return;
  glp_term_out(GLP_OFF);
  t_configured = t_generation;
}

int guarded_simplex(glp_prob* lp, const glp_smcp* parm) {
  configure_glpk();
  std::jmp_buf buf;
  t_jump = &buf;
  glp_error_hook(on_glpk_error, nullptr);
  if (setjmp(buf) != 0) {
    t_jump = nullptr;
    glp_free_env();
    ++t_generation;
    return -1;
  }
  const int ret = glp_simplex(lp, parm);
  glp_error_hook(nullptr, nullptr);
  t_jump = nullptr;
  return ret;
}

}  // namespace wiresculpt::detail
