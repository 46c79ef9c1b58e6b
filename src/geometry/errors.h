// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The error policy of surftex (docs/STYLE.md 6): library code throws one of these,
// with the offending parameter or file and value in the message; it never exits.
// The CLI turns them into "error: <message>" and exit code 2.

#include <stdexcept>
#include <string>

namespace surftex {

/// Base of every surftex error.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A parameter or input value is out of range, malformed or inconsistent.
class InvalidInputError : public Error {
 public:
  using Error::Error;
};

/// The mesh has a topology the algorithm cannot handle (non-manifold, open, ...).
class TopologyError : public Error {
 public:
  using Error::Error;
};

/// A numerical solver failed (factorisation, non-convergence, TetGen refusal).
class SolverError : public Error {
 public:
  using Error::Error;
};

/// A file could not be read, parsed or written.
class IOError : public Error {
 public:
  using Error::Error;
};

}  // namespace surftex
