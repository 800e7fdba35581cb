// What `simbot --version` prints, for the simbot executable and the Python
// module alike: a batch records it in its settings (batch.json) and
// --resume refuses a batch that another build of simbot began, so both
// front ends must say the same (their own library, so that a new commit
// relinks these two and nothing else).
#pragma once
#include <string>

namespace simbot::cli {

// "simbot 0.1.0 (commit 0123456789ab, RelWithDebInfo build, SUNDIALS 6.4.1)";
// the commit has "-dirty" when the build's tracked files differed from it.
std::string simbotVersion();

}  // namespace simbot::cli
