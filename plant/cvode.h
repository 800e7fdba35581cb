// plant/cvode.h -- internal: RAII owners for the SUNDIALS 6.x objects.
//
// CVODE hands out raw handles that must be freed in the right order (the
// CVODE memory and the linear solver refer to the vector, matrix and
// context). Each wrapper owns one handle, is move-only, and frees it in its
// destructor; Arena::Impl declares them in creation order so C++'s reverse
// destruction order frees them correctly. A failing SUNDIALS call throws
// SolverError (plant.h) naming the call: the run ends with a fault of the
// plant.
#pragma once

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <stdexcept>
#include <string>
#include <utility>

#include "plant/plant.h"

namespace simbot::plant::cv {

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
    // CVODE's clones inherit this: one pass for each linear combination
    // (dense output, prediction) instead of one call per term. Same sums in
    // the same order, so the same bits (the 180-s match's trace is
    // byte-identical); 3 % of a default-profile match.
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

// Functional (fixed-point) iteration for the corrector: the right answer
// for a non-stiff problem, with no Jacobian and no linear solve.
class FixedPointSolver {
 public:
  FixedPointSolver(N_Vector y, SUNContext ctx) : s_(SUNNonlinSol_FixedPoint(y, 0, ctx)) {
    if (!s_) throw std::runtime_error("SUNDIALS: SUNNonlinSol_FixedPoint failed");
  }
  ~FixedPointSolver() {
    if (s_) SUNNonlinSolFree(s_);
  }
  FixedPointSolver(const FixedPointSolver&) = delete;
  FixedPointSolver& operator=(const FixedPointSolver&) = delete;
  SUNNonlinearSolver get() const { return s_; }

 private:
  SUNNonlinearSolver s_;
};

class Memory {
 public:
  Memory(int lmm, SUNContext ctx) : mem_(CVodeCreate(lmm, ctx)) {
    if (!mem_) throw std::runtime_error("SUNDIALS: CVodeCreate failed");
  }
  ~Memory() {
    if (mem_) CVodeFree(&mem_);
  }
  Memory(const Memory&) = delete;
  Memory& operator=(const Memory&) = delete;
  void* get() const { return mem_; }

 private:
  void* mem_;
};

}  // namespace simbot::plant::cv
