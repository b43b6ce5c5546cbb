#pragma once
// Errors the core throws. The core never prints: a stage either returns its value or throws one
// of these with a sentence a user can act on, naming the wire, plane, crossing or key at fault.
// The Python binding maps InputError to ValueError and SolverError to RuntimeError.
#include <stdexcept>
#include <string>

namespace wiresculpt {

/// Base of every error the core throws.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The input is wrong (NaN coordinates, a zero normal, an index out of range ...).
class InputError : public Error {
 public:
  using Error::Error;
};

/// The input was valid but a stage could not finish (no stable layering, an optimiser failure).
class SolverError : public Error {
 public:
  using Error::Error;
};

/// The progress callback asked to stop.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

}  // namespace wiresculpt
