// plant/arkode.h -- internal: RAII owners for the SUNDIALS 6.x objects.
//
// ARKODE hands out raw handles that must be freed in the right order (the
// ERKStep memory refers to the vector and the context). Each wrapper owns
// one handle, is move-only, and frees it in its destructor; Arena::Impl
// declares them in creation order so C++'s reverse destruction order frees
// them correctly. A failing SUNDIALS call throws SolverError (plant.h)
// naming the call: the run ends with a fault of the plant.
#pragma once

#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <stdexcept>
#include <string>

#include "plant/plant.h"

namespace simbot::plant::ark {

inline void check(int flag, const char* what) {
  if (flag < 0)
    throw SolverError(std::string("SUNDIALS: ") + what + " failed, flag " + std::to_string(flag));
}

class Context {
 public:
  Context() { check(SUNContext_Create(nullptr, &ctx_), "SUNContext_Create"); }
  ~Context() {
    if (ctx_) SUNContext_Free(&ctx_);
  }
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  SUNContext get() const { return ctx_; }

 private:
  SUNContext ctx_ = nullptr;
};

class Vector {
 public:
  Vector(sunindextype n, SUNContext ctx) : v_(N_VNew_Serial(n, ctx)) {
    if (!v_) throw std::runtime_error("SUNDIALS: N_VNew_Serial failed");
    // ARKODE's clones inherit this: one pass for each linear combination
    // (the Runge-Kutta stages) instead of one call per term.
    if (N_VEnableFusedOps_Serial(v_, SUNTRUE) != 0) {
      N_VDestroy(v_);
      throw std::runtime_error("SUNDIALS: N_VEnableFusedOps_Serial failed");
    }
  }
  ~Vector() {
    if (v_) N_VDestroy(v_);
  }
  Vector(const Vector&) = delete;
  Vector& operator=(const Vector&) = delete;
  N_Vector get() const { return v_; }
  double* data() const { return N_VGetArrayPointer(v_); }

 private:
  N_Vector v_;
};

// The ERKStep integrator's memory.
class ErkMemory {
 public:
  ErkMemory(ARKRhsFn f, double t0, N_Vector y0, SUNContext ctx)
      : mem_(ERKStepCreate(f, t0, y0, ctx)) {
    if (!mem_) throw std::runtime_error("SUNDIALS: ERKStepCreate failed");
  }
  ~ErkMemory() {
    if (mem_) ERKStepFree(&mem_);
  }
  ErkMemory(const ErkMemory&) = delete;
  ErkMemory& operator=(const ErkMemory&) = delete;
  void* get() const { return mem_; }

 private:
  void* mem_;
};

}  // namespace simbot::plant::ark
