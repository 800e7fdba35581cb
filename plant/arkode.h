// plant/arkode.h -- internal: the plant's one door to SUNDIALS ARKODE.
//
// The arena integrates the robots' centres with ARKODE's ERKStep. Only
// arkode.cpp names SUNDIALS (its headers, types and calls), so a new
// SUNDIALS release changes that file alone: it is written for 6.x (from
// 6.4) and 7.x, with version tests where their APIs differ and the names
// that are not deprecated where both have one (plant/CMakeLists.txt finds
// a SUNDIALS in that range). This interface speaks plain arrays of
// doubles: one Integrator owns the context, its two vectors and the
// ERKStep memory and frees them in the right order; after its constructor
// it allocates nothing (ARKODE itself only when the number of root
// functions changes). A failing call throws SolverError (plant.h) naming
// the SUNDIALS function: the run ends with a fault of the plant.
#pragma once

#include <memory>

namespace simbot::plant::ark {

// The right-hand side y' = f(t, y) and the root functions g(t, y) (one
// value each), over arrays of the integrator's size; `user` is the pointer
// given to the Integrator.
using RhsFn = void (*)(double t, const double* y, double* ydot, void* user);
using RootFn = void (*)(double t, const double* y, double* g, void* user);

// How a step() call ended (ARK_SUCCESS, ARK_TSTOP_RETURN, ARK_ROOT_RETURN).
enum class StepEnd { Step, StopTime, Root };

// One of the integrator's two vectors: the state that reset() starts from
// and step() returns into, and a second one for interpolation.
enum class Buffer { State, Scratch };

// The serial vector operations ARKODE works with: arkode.cpp's own for
// the hot ones (the same arithmetic as SUNDIALS' serial vector, compiled
// with optimisation, which distributions' SUNDIALS is not), or SUNDIALS'
// throughout, to check those against (tests/plant/arkode_test.cpp).
enum class VectorOps { Own, Sundials };

class Integrator {
 public:
  // n values, starting at t = 0 from state() as it is (zeros).
  Integrator(int n, RhsFn rhs, void* user, VectorOps ops = VectorOps::Own);
  ~Integrator();
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  double* data(Buffer b) const { return b == Buffer::State ? state_ : scratch_; }

  // The method and its limits (once, after construction).
  void useDormandPrince745();
  void setTolerances(double relative, double absolute);
  void setMaxNumSteps(long steps);

  // A new start at t0 from data(Buffer::State); the step counters and the
  // step controller's history go on (ERKStep's reset).
  void reset(double t0);
  void setInitStep(double h);  // 0: ARKODE's own estimate
  void setMaxStep(double h);
  // n root functions, all evaluated by g (n = 0: none).
  void setRoots(int n, RootFn g);
  void setStopTime(double t);

  // One internal step (ARKODE's one-step mode) into `into`; tret is the time
  // returned. tout, ahead of the current time, only guides the first
  // step's size after creation or a reset.
  StepEnd step(double tout, Buffer into, double& tret);
  double currentTime() const;  // end of the last internal step
  double currentStep() const;  // the step ARKODE plans next
  // ARKODE's own interpolant at t (within the last step) into `into`.
  void interpolate(double t, Buffer into);
  // After a StepEnd::Root: for each root function, +1 or -1 where it
  // crossed (rising, falling), 0 elsewhere.
  void rootsFound(int* found) const;

  long steps() const;     // internal steps since construction
  long rhsEvals() const;  // calls of the right-hand side, likewise

 private:
  // The SUNDIALS objects and the callbacks ARKODE calls (arkode.cpp).
  struct Handles;
  std::unique_ptr<Handles> h_;
  void* mem_ = nullptr;  // the ERKStep memory, at hand for every call
  double* state_ = nullptr;
  double* scratch_ = nullptr;
};

}  // namespace simbot::plant::ark
