// plant/last_call.h -- internal: a pure function's last argument and value.
#pragma once

#include <cstdint>
#include <cstring>

namespace simbot::plant {

// The last argument and value of a pure function of one double: the same
// argument, bit for bit, gives back the same value without the call (the
// value is the one the call made; -0 and +0 are different arguments). The
// arena's closed forms are evaluated again and again at one time (a step's
// end, both robots, the eyes' two poses), the eyes' far-eye angle for the
// same profile on every read.
template <double (*F)(double)>
class LastCall {
 public:
  double operator()(double x) {
    std::uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    if (!valid_ || bits != arg_) {
      arg_ = bits;
      value_ = F(x);
      valid_ = true;
    }
    return value_;
  }

 private:
  std::uint64_t arg_ = 0;
  double value_ = 0;
  bool valid_ = false;
};
}  // namespace simbot::plant
