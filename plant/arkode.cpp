// plant/arkode.cpp -- the adapter to SUNDIALS ARKODE (arkode.h): the one
// file that includes SUNDIALS' headers and calls it.
//
// Versions 6.4 to 7.x. Where they differ:
// - 7.0 made SUNContext_Create take a SUNComm (SUN_COMM_NULL without a
//   communicator; 6.x took a void*, null) and removed ERKStepSetErrFile:
//   errors go to the handlers on the context's stack, warnings to its
//   logger.
// - 7.1 gave the calls that every ARKODE stepper shares ARKODE-level names
//   (ARKodeEvolve for ERKStepEvolve, ...) and deprecated ERKStep's;
//   ERKStepCreate and ERKStepSetTableNum stay ERKStep's own.
// - 7.2 did the same for the count of right-hand sides
//   (ARKodeGetNumRhsEvals).
// The calls, their order and their arguments are the same in every
// version: the numbers come from ARKODE alone.
#include <arkode/arkode.h>
#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_config.h>
#include <sundials/sundials_context.h>
#if SUNDIALS_VERSION_MAJOR >= 7
#include <sundials/sundials_logger.h>
#endif

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "plant/arkode.h"
#include "plant/plant.h"

#if SUNDIALS_VERSION_MAJOR < 6 || (SUNDIALS_VERSION_MAJOR == 6 && SUNDIALS_VERSION_MINOR < 4) || \
    SUNDIALS_VERSION_MAJOR > 7
#error "plant/arkode.cpp is written for SUNDIALS 6.4 to 7.x (plant/CMakeLists.txt)"
#endif
static_assert(std::is_same_v<sunrealtype, double>, "the plant needs SUNDIALS built for double");

// A call ERKStep shares with the other steppers: by its ARKODE-level name
// from 7.1 on, by ERKStep's before.
#if SUNDIALS_VERSION_MAJOR > 7 || (SUNDIALS_VERSION_MAJOR == 7 && SUNDIALS_VERSION_MINOR >= 1)
#define SIMBOT_ARK(fn) ARKode##fn
#else
#define SIMBOT_ARK(fn) ERKStep##fn
#endif
#define SIMBOT_ARK_QUOTE(x) #x
#define SIMBOT_ARK_NAME(x) SIMBOT_ARK_QUOTE(x)
// Makes the shared call `fn` and throws SolverError naming it if it fails.
#define SIMBOT_ARK_CALL(fn, ...) check(SIMBOT_ARK(fn)(__VA_ARGS__), SIMBOT_ARK_NAME(SIMBOT_ARK(fn)))

namespace simbot::plant {

const char* sundialsVersion() { return SUNDIALS_VERSION; }

namespace ark {

namespace {

void check(int flag, const char* what) {
  if (flag < 0)
    throw SolverError(std::string("SUNDIALS: ") + what + " failed, flag " + std::to_string(flag));
}

// The serial vector's linear combination and scaling, the operations a
// Runge-Kutta step makes most (ARKODE's stages and solutions, about eight
// of each a step), with the arithmetic of N_VLinearCombination_Serial and
// N_VScale_Serial: every branch, and in each element the same products and
// sums in the same order (no contraction: -ffp-contract=off), so the same
// bits. Distributions build SUNDIALS without optimisation (Debian's 6.4.1
// spills every loop counter to the stack): a call on our four-element
// vectors cost about 620 instructions there, here a tenth of that. A
// combination of one or two vectors is left to SUNDIALS' own scaling and
// linear sum, as N_VLinearCombination_Serial leaves it.
bool combineFour(int nvec, const sunrealtype* c, N_Vector* X, N_Vector z, sunrealtype* zd) {
  for (int i = 1; i < nvec; ++i) {
    const sunrealtype* x = NV_DATA_S(X[i]);
    if (std::less<>()(x, zd + 4) && std::less<>()(zd, x + 4)) return false;
  }
  sunrealtype z0, z1, z2, z3;
  if (X[0] == z) {
    z0 = zd[0], z1 = zd[1], z2 = zd[2], z3 = zd[3];
    if (c[0] != 1.0) z0 *= c[0], z1 *= c[0], z2 *= c[0], z3 *= c[0];
  } else {
    const sunrealtype* x = NV_DATA_S(X[0]);
    z0 = c[0] * x[0], z1 = c[0] * x[1], z2 = c[0] * x[2], z3 = c[0] * x[3];
  }
  for (int i = 1; i < nvec; ++i) {
    const sunrealtype* x = NV_DATA_S(X[i]);
    z0 += c[i] * x[0];
    z1 += c[i] * x[1];
    z2 += c[i] * x[2];
    z3 += c[i] * x[3];
  }
  zd[0] = z0, zd[1] = z1, zd[2] = z2, zd[3] = z3;
  return true;
}

int linearCombination(int nvec, sunrealtype* c, N_Vector* X, N_Vector z) {
  if (nvec < 1) return -1;
  if (nvec == 1) {
    N_VScale_Serial(c[0], X[0], z);
    return 0;
  }
  if (nvec == 2) {
    N_VLinearSum_Serial(c[0], X[0], c[1], X[1], z);
    return 0;
  }
  const sunindextype n = NV_LENGTH_S(z);
  sunrealtype* zd = NV_DATA_S(z);
  // The arena's two robots: four values, summed in registers while no term
  // shares memory with z (else a term would be read before or after
  // SUNDIALS' order had updated it).
  if (n == 4 && combineFour(nvec, c, X, z, zd)) return 0;
  if (X[0] == z) {
    if (c[0] != 1.0)
      for (sunindextype j = 0; j < n; ++j) zd[j] *= c[0];
  } else {
    const sunrealtype* xd = NV_DATA_S(X[0]);
    for (sunindextype j = 0; j < n; ++j) zd[j] = c[0] * xd[j];
  }
  for (int i = 1; i < nvec; ++i) {
    const sunrealtype* xd = NV_DATA_S(X[i]);
    for (sunindextype j = 0; j < n; ++j) zd[j] += c[i] * xd[j];
  }
  return 0;
}

void scale(sunrealtype c, N_Vector x, N_Vector z) {
  const sunindextype n = NV_LENGTH_S(x);
  const sunrealtype* xd = NV_DATA_S(x);
  sunrealtype* zd = NV_DATA_S(z);
  if (z == x) {
    for (sunindextype j = 0; j < n; ++j) zd[j] *= c;
  } else if (c == 1.0) {
    for (sunindextype j = 0; j < n; ++j) zd[j] = xd[j];
  } else if (c == -1.0) {
    for (sunindextype j = 0; j < n; ++j) zd[j] = -xd[j];
  } else {
    for (sunindextype j = 0; j < n; ++j) zd[j] = c * xd[j];
  }
}

// The error weights' operations (ARKODE's 1 / (rtol |y| + atol), each
// step) and the weighted RMS norm of the error test, likewise:
// SUNRsqrt gives 0 for a mean square <= 0, and no square root of -0.
void absolute(N_Vector x, N_Vector z) {
  const sunindextype n = NV_LENGTH_S(x);
  const sunrealtype* xd = NV_DATA_S(x);
  sunrealtype* zd = NV_DATA_S(z);
  for (sunindextype j = 0; j < n; ++j) zd[j] = std::fabs(xd[j]);
}

void inverse(N_Vector x, N_Vector z) {
  const sunindextype n = NV_LENGTH_S(x);
  const sunrealtype* xd = NV_DATA_S(x);
  sunrealtype* zd = NV_DATA_S(z);
  for (sunindextype j = 0; j < n; ++j) zd[j] = 1.0 / xd[j];
}

void addConstant(N_Vector x, sunrealtype b, N_Vector z) {
  const sunindextype n = NV_LENGTH_S(x);
  const sunrealtype* xd = NV_DATA_S(x);
  sunrealtype* zd = NV_DATA_S(z);
  for (sunindextype j = 0; j < n; ++j) zd[j] = xd[j] + b;
}

sunrealtype wrmsNorm(N_Vector x, N_Vector w) {
  const sunindextype n = NV_LENGTH_S(x);
  const sunrealtype* xd = NV_DATA_S(x);
  const sunrealtype* wd = NV_DATA_S(w);
  sunrealtype sum = 0.0;
  for (sunindextype j = 0; j < n; ++j) {
    const sunrealtype p = xd[j] * wd[j];
    sum += p * p;
  }
  const sunrealtype mean = sum / static_cast<sunrealtype>(n);
  return mean <= 0.0 ? 0.0 : std::sqrt(mean);
}

N_Vector newVector(int n, SUNContext ctx, VectorOps ops) {
  N_Vector v = N_VNew_Serial(static_cast<sunindextype>(n), ctx);
  if (!v) throw std::runtime_error("SUNDIALS: N_VNew_Serial failed");
  // ARKODE's clones inherit this: one pass for each linear combination
  // (the Runge-Kutta stages) instead of one call per term.
  if (N_VEnableFusedOps_Serial(v, SUNTRUE) != 0) {
    N_VDestroy(v);
    throw std::runtime_error("SUNDIALS: N_VEnableFusedOps_Serial failed");
  }
  if (ops == VectorOps::Sundials) return v;
  // (Clones copy the operations too.)
  v->ops->nvlinearcombination = &linearCombination;
  v->ops->nvscale = &scale;
  v->ops->nvabs = &absolute;
  v->ops->nvinv = &inverse;
  v->ops->nvaddconst = &addConstant;
  v->ops->nvwrmsnorm = &wrmsNorm;
  return v;
}

}  // namespace

// Freed in the reverse order of creation: the ERKStep memory refers to the
// vectors' context.
struct Integrator::Handles {
  SUNContext ctx = nullptr;
  N_Vector state = nullptr;
  N_Vector scratch = nullptr;
  void* mem = nullptr;
  RhsFn rhs = nullptr;
  RootFn root = nullptr;
  void* user = nullptr;

  Handles() = default;
  Handles(const Handles&) = delete;
  Handles& operator=(const Handles&) = delete;
  ~Handles() {
    if (mem) SIMBOT_ARK(Free)(&mem);
    if (scratch) N_VDestroy(scratch);
    if (state) N_VDestroy(state);
    if (ctx) SUNContext_Free(&ctx);
  }

  N_Vector vector(Buffer b) const { return b == Buffer::State ? state : scratch; }

  static int rhsThunk(sunrealtype t, N_Vector y, N_Vector ydot, void* self) {
    const Handles* h = static_cast<const Handles*>(self);
    // Every vector is a serial one (ours or ARKODE's clones of it): its
    // data directly, not through N_VGetArrayPointer's two calls.
    h->rhs(t, NV_DATA_S(y), NV_DATA_S(ydot), h->user);
    return 0;
  }
  static int rootThunk(sunrealtype t, N_Vector y, sunrealtype* g, void* self) {
    const Handles* h = static_cast<const Handles*>(self);
    h->root(t, NV_DATA_S(y), g, h->user);
    return 0;
  }
};

Integrator::Integrator(int n, RhsFn rhs, void* user, VectorOps ops)
    : h_(std::make_unique<Handles>()) {
  Handles& h = *h_;
  h.rhs = rhs;
  h.user = user;
#if SUNDIALS_VERSION_MAJOR >= 7
  check(SUNContext_Create(SUN_COMM_NULL, &h.ctx), "SUNContext_Create");
  // No error handler: a failure reaches the plant as its call's flag (a
  // SolverError, the run's plant fault), not as a line on stderr.
  check(SUNContext_ClearErrHandlers(h.ctx), "SUNContext_ClearErrHandlers");
#if SUNDIALS_LOGGING_LEVEL >= 2  // SUN_LOGLEVEL_WARNING
  // A build that logs warnings prints them to stdout, simbot's JSON and
  // trace output, unless told otherwise (6.x sent them to the error file,
  // which was none).
  SUNLogger logger = nullptr;
  check(SUNContext_GetLogger(h.ctx, &logger), "SUNContext_GetLogger");
  check(SUNLogger_SetWarningFilename(logger, "/dev/null"), "SUNLogger_SetWarningFilename");
#endif
#else
  check(SUNContext_Create(nullptr, &h.ctx), "SUNContext_Create");
#endif
  h.state = newVector(n, h.ctx, ops);
  h.scratch = newVector(n, h.ctx, ops);
  h.mem = ERKStepCreate(&Handles::rhsThunk, 0.0, h.state, h.ctx);
  if (!h.mem) throw std::runtime_error("SUNDIALS: ERKStepCreate failed");
  mem_ = h.mem;
  state_ = N_VGetArrayPointer(h.state);
  scratch_ = N_VGetArrayPointer(h.scratch);
  SIMBOT_ARK_CALL(SetUserData, mem_, h_.get());
#if SUNDIALS_VERSION_MAJOR < 7
  // ARKODE's own messages would go to stderr.
  check(ERKStepSetErrFile(mem_, nullptr), "ERKStepSetErrFile");
#endif
}

Integrator::~Integrator() = default;

void Integrator::useDormandPrince745() {
  check(ERKStepSetTableNum(mem_, ARKODE_DORMAND_PRINCE_7_4_5), "ERKStepSetTableNum");
}

void Integrator::setTolerances(double relative, double absolute) {
  SIMBOT_ARK_CALL(SStolerances, mem_, relative, absolute);
}

void Integrator::setMaxNumSteps(long steps) { SIMBOT_ARK_CALL(SetMaxNumSteps, mem_, steps); }

void Integrator::reset(double t0) { SIMBOT_ARK_CALL(Reset, mem_, t0, h_->state); }

void Integrator::setInitStep(double h) { SIMBOT_ARK_CALL(SetInitStep, mem_, h); }

void Integrator::setMaxStep(double h) { SIMBOT_ARK_CALL(SetMaxStep, mem_, h); }

void Integrator::setRoots(int n, RootFn g) {
  h_->root = g;
  SIMBOT_ARK_CALL(RootInit, mem_, n, n > 0 ? &Handles::rootThunk : nullptr);
  // (the root memory exists only now)
  if (n > 0) SIMBOT_ARK_CALL(SetNoInactiveRootWarn, mem_);
}

void Integrator::setStopTime(double t) { SIMBOT_ARK_CALL(SetStopTime, mem_, t); }

StepEnd Integrator::step(double tout, Buffer into, double& tret) {
  const int flag = SIMBOT_ARK(Evolve)(mem_, tout, h_->vector(into), &tret, ARK_ONE_STEP);
  check(flag, SIMBOT_ARK_NAME(SIMBOT_ARK(Evolve)));
  if (flag == ARK_ROOT_RETURN) return StepEnd::Root;
  if (flag == ARK_TSTOP_RETURN) return StepEnd::StopTime;
  return StepEnd::Step;
}

double Integrator::currentTime() const {
  double t = 0;
  SIMBOT_ARK_CALL(GetCurrentTime, mem_, &t);
  return t;
}

double Integrator::currentStep() const {
  double h = 0;
  SIMBOT_ARK_CALL(GetCurrentStep, mem_, &h);
  return h;
}

void Integrator::interpolate(double t, Buffer into) {
  SIMBOT_ARK_CALL(GetDky, mem_, t, 0, h_->vector(into));
}

void Integrator::rootsFound(int* found) const { SIMBOT_ARK_CALL(GetRootInfo, mem_, found); }

long Integrator::steps() const {
  long n = 0;
  SIMBOT_ARK_CALL(GetNumSteps, mem_, &n);
  return n;
}

long Integrator::rhsEvals() const {
  long n = 0;
#if SUNDIALS_VERSION_MAJOR > 7 || (SUNDIALS_VERSION_MAJOR == 7 && SUNDIALS_VERSION_MINOR >= 2)
  check(ARKodeGetNumRhsEvals(mem_, 0, &n), "ARKodeGetNumRhsEvals");  // ERKStep's one partition
#else
  check(ERKStepGetNumRhsEvals(mem_, &n), "ERKStepGetNumRhsEvals");
#endif
  return n;
}

}  // namespace ark
}  // namespace simbot::plant
