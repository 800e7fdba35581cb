// inspect/names.h -- internal: what a name in an expression means from a
// Scope (names.cpp), by C's rules of scope. Nothing outside inspect/
// includes this header.
#pragma once
#include <string>

#include "inspect/inspect.h"

namespace simbot::inspect {

// The symbol NAME means from the selected frame, or FUNCTION::NAME.
struct Found {
  const vm::Symbol* symbol = nullptr;
  int frame = -1;  // autos: the activation whose frame holds it
};
Found lookUp(const Scope& s, const std::string& function, const std::string& name);
// The object a symbol names; `typesOnly`: an auto's frame need not exist.
Value objectOf(const Scope& s, const Found& found, bool typesOnly = false);

}  // namespace simbot::inspect
