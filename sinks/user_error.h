// The error every part above the simulator (sinks/, reports/, runs/,
// batch/, cli/) throws for a user's mistake: a file that cannot be read or
// written, a bad option, a bad trace line. Its message is complete, as the
// user sees it; the command line prints it as is and exits with status 1.
// It lives here, in the lowest of those parts, so that they all share it.
#pragma once
#include <stdexcept>

namespace simbot::sinks {

struct UserError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace simbot::sinks
