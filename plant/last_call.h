// plant/last_call.h -- internal: a pure function's last argument and value.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace simbot::plant {

// The last argument and value of a pure function of one double: the same
// argument, bit for bit, gives back the same value without the call (the
// value is the one the call made; -0 and +0 are different arguments). It
// starts as the call at +0, so every value it holds is one F made. The
// arena's closed forms are evaluated again and again at one time (a step's
// end, both robots, the eyes' two poses), the eyes' far-eye angle for the
// same profile on every read.
template <auto F>
class LastCall {
 public:
  using Value = std::invoke_result_t<decltype(F), double>;
  LastCall() : value_(F(0.0)) {}
  Value operator()(double x) {
    std::uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    if (bits != arg_) {
      arg_ = bits;
      value_ = F(x);
    }
    return value_;
  }

 private:
  std::uint64_t arg_ = 0;  // the bits of +0
  Value value_;
};
}  // namespace simbot::plant
