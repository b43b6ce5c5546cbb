#pragma once
// A Python progress callable as the core's ProgressFn, and the one way bindings run core work
// with the GIL released.
//
// The callable is held by pointer (it lives in the binding's frame), so copying the ProgressFn
// inside the core never touches reference counts without the GIL. It is called with the GIL
// held; returning None or True continues, False cancels. If it raises, the core is cancelled and
// the callable's own exception is re-raised to Python instead of Cancelled.
#include <pybind11/pybind11.h>

#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "wiresculpt/progress.hpp"

namespace wiresculpt::python {

class PythonProgress {
 public:
  explicit PythonProgress(const pybind11::object& callable) : callable_(callable.is_none() ? nullptr : &callable) {}
  PythonProgress(const PythonProgress&) = delete;
  PythonProgress& operator=(const PythonProgress&) = delete;

  ProgressFn fn() {
    if (!callable_) return {};
    return [this](std::string_view stage, double fraction) {
      pybind11::gil_scoped_acquire acquire;
      try {
        const pybind11::object r = (*callable_)(std::string(stage), fraction);
        return r.is_none() || pybind11::cast<bool>(r);
      } catch (...) {
        error_ = std::current_exception();
        return false;  // stop the core, then re-raise below
      }
    };
  }

  /// Runs `work` with the GIL released; afterwards re-raises the callable's exception if it
  /// raised one, else whatever `work` threw.
  template <class Work>
  auto run(Work&& work) -> decltype(work()) {
    std::exception_ptr core_error;
    std::optional<decltype(work())> result;
    {
      pybind11::gil_scoped_release release;
      try {
        result.emplace(work());
      } catch (...) {
        core_error = std::current_exception();
      }
    }
    if (error_) std::rethrow_exception(error_);
    if (core_error) std::rethrow_exception(core_error);
    return std::move(*result);
  }

 private:
  const pybind11::object* callable_;
  std::exception_ptr error_;
};

}  // namespace wiresculpt::python
