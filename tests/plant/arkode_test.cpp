// The ARKODE adapter (plant/arkode.h) on its own, with whichever SUNDIALS
// the build found (6.x in the normal build, 7.x in build-sundials7):
// every call it offers, against closed forms. The problem is the harmonic
// oscillator y0' = y1, y1' = -y0 from (0, 1) at t = 0, whose solution is
// (sin t, cos t); its roots are those of sin and cos.
#include "plant/arkode.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <string>

#include "plant/plant.h"

namespace {

using simbot::plant::SolverError;
using simbot::plant::ark::Buffer;
using simbot::plant::ark::Integrator;
using simbot::plant::ark::StepEnd;

constexpr double kPi = std::numbers::pi;

struct Oscillator {
  long rhsCalls = 0;

  static void rhs(double, const double* y, double* ydot, void* user) {
    ++static_cast<Oscillator*>(user)->rhsCalls;
    ydot[0] = y[1];
    ydot[1] = -y[0];
  }
  static void roots(double, const double* y, double* g, void*) {
    g[0] = y[1];        // cos: falls through 0 at pi/2
    g[1] = y[0] - 0.5;  // sin - 1/2: rises through 0 at pi/6
  }
};

// An integrator at the plant's tolerances, started at t = 0 from (0, 1).
struct Fixture {
  Oscillator osc;
  Integrator ode{2, &Oscillator::rhs, &osc};
  Fixture() {
    ode.useDormandPrince745();
    ode.setTolerances(3e-11, 1e-10);
    ode.setMaxNumSteps(100000);
    ode.data(Buffer::State)[0] = 0.0;
    ode.data(Buffer::State)[1] = 1.0;
    ode.reset(0.0);
  }
  // Steps until ARKODE returns at or past t; the last return's end, and in
  // tprev the time of the return before it.
  StepEnd stepPast(double t, double& tret, double& tprev) {
    StepEnd end = StepEnd::Step;
    tret = tprev = ode.currentTime();
    while (tret < t) {
      tprev = tret;
      end = ode.step(tret + 1.0, Buffer::State, tret);
    }
    return end;
  }
};

TEST(Arkode, StepsFollowTheClosedFormAndInterpolateWithinTheLastStep) {
  Fixture f;
  double tret = 0, tprev = 0;
  EXPECT_EQ(f.stepPast(2.0, tret, tprev), StepEnd::Step);
  EXPECT_EQ(tret, f.ode.currentTime());  // no root, no stop: the step's end
  const double* y = f.ode.data(Buffer::State);
  EXPECT_NEAR(y[0], std::sin(tret), 1e-9);
  EXPECT_NEAR(y[1], std::cos(tret), 1e-9);
  // Half-way through the last step, on ARKODE's interpolant.
  const double t = 0.5 * (tprev + tret);
  ASSERT_LT(tprev, t);
  f.ode.interpolate(t, Buffer::Scratch);
  EXPECT_NEAR(f.ode.data(Buffer::Scratch)[0], std::sin(t), 1e-9);
  EXPECT_NEAR(f.ode.data(Buffer::Scratch)[1], std::cos(t), 1e-9);
  EXPECT_GT(f.ode.currentStep(), 0.0);
}

TEST(Arkode, RootsComeInOrderWithTheirDirections) {
  Fixture f;
  f.ode.setRoots(2, &Oscillator::roots);
  double tret = 0;
  int found[2] = {7, 7};
  // sin t - 1/2 rises through 0 at pi/6 first, then cos t falls at pi/2.
  StepEnd end = f.ode.step(tret + 1.0, Buffer::State, tret);
  while (end == StepEnd::Step) end = f.ode.step(tret + 1.0, Buffer::State, tret);
  ASSERT_EQ(end, StepEnd::Root);
  EXPECT_NEAR(tret, kPi / 6, 1e-9);
  f.ode.rootsFound(found);
  EXPECT_EQ(found[0], 0);
  EXPECT_EQ(found[1], 1);
  end = f.ode.step(tret + 1.0, Buffer::State, tret);
  while (end == StepEnd::Step) end = f.ode.step(tret + 1.0, Buffer::State, tret);
  ASSERT_EQ(end, StepEnd::Root);
  EXPECT_NEAR(tret, kPi / 2, 1e-9);
  f.ode.rootsFound(found);
  EXPECT_EQ(found[0], -1);
  EXPECT_EQ(found[1], 0);
  // At a root return the state vector holds the state at the root.
  EXPECT_NEAR(f.ode.data(Buffer::State)[0], 1.0, 1e-9);
  EXPECT_NEAR(f.ode.data(Buffer::State)[1], 0.0, 1e-9);
  // No root functions: nothing stops it before t = 4 (past 3 pi / 2 and
  // 5 pi / 6, where the two would cross again).
  f.ode.setRoots(0, nullptr);
  double tprev = 0;
  EXPECT_EQ(f.stepPast(4.0, tret, tprev), StepEnd::Step);
}

TEST(Arkode, AStopTimeIsReturnedExactlyAndAResetStartsAgainThere) {
  Fixture f;
  f.ode.setStopTime(1.0);
  double tret = 0;
  StepEnd end = StepEnd::Step;
  while (end == StepEnd::Step) end = f.ode.step(10.0, Buffer::State, tret);
  EXPECT_EQ(end, StepEnd::StopTime);
  EXPECT_EQ(tret, 1.0);
  EXPECT_NEAR(f.ode.data(Buffer::State)[0], std::sin(1.0), 1e-9);
  // A new start at t = 5 from (0, 1): the solution is then (sin(t - 5),
  // cos(t - 5)), and the stop time, reached, no longer holds.
  f.ode.data(Buffer::State)[0] = 0.0;
  f.ode.data(Buffer::State)[1] = 1.0;
  f.ode.reset(5.0);
  f.ode.setInitStep(0.01);
  f.ode.setMaxStep(0.25);
  double tprev = 0;
  EXPECT_EQ(f.stepPast(7.0, tret, tprev), StepEnd::Step);
  EXPECT_NEAR(f.ode.data(Buffer::State)[0], std::sin(tret - 5.0), 1e-9);
  EXPECT_NEAR(f.ode.data(Buffer::State)[1], std::cos(tret - 5.0), 1e-9);
  EXPECT_LE(tret - tprev, 0.25);  // the maximum step holds
  EXPECT_LE(f.ode.currentStep(), 0.25);
}

// The counters are ARKODE's over the integrator's life: its steps are the
// returns that ended a new step, its right-hand sides the calls of the
// function given (counted by the function itself).
TEST(Arkode, CountersAreTheStepsTakenAndTheRightHandSidesCalled) {
  Fixture f;
  f.ode.setRoots(2, &Oscillator::roots);
  long steps = 0;
  double tret = 0, tEnd = 0;
  while (tret < 3.0) {
    f.ode.step(tret + 1.0, Buffer::State, tret);
    if (f.ode.currentTime() > tEnd) {
      ++steps;
      tEnd = f.ode.currentTime();
    }
  }
  EXPECT_EQ(f.ode.steps(), steps);
  EXPECT_GT(steps, 10);
  EXPECT_EQ(f.ode.rhsEvals(), f.osc.rhsCalls);
}

// One or two oscillators of different frequencies (two or four values;
// four as the arena's two robots' x and y): y0' = y1, y1' = -y0,
// y2' = 3 y3, y3' = -3 y2. `user` points to the count.
void oscillators(double, const double* y, double* ydot, void* user) {
  ydot[0] = y[1];
  ydot[1] = -y[0];
  if (*static_cast<const int*>(user) == 4) {
    ydot[2] = 3 * y[3];
    ydot[3] = -3 * y[2];
  }
}
void oscillatorRoots(double, const double* y, double* g, void*) {
  g[0] = y[1];
  g[1] = y[0] - 0.25;
}

// arkode.cpp's own vector operations against SUNDIALS' serial ones, which
// they replace, for n values: the same steps, roots, stop time, reset and
// interpolation give the same numbers, bit for bit.
void compareWithSundials(int n) {
  using simbot::plant::ark::VectorOps;
  Integrator own{n, &oscillators, &n, VectorOps::Own};
  Integrator ref{n, &oscillators, &n, VectorOps::Sundials};
  for (Integrator* ode : {&own, &ref}) {
    ode->useDormandPrince745();
    ode->setTolerances(3e-11, 1e-10);
    ode->setMaxNumSteps(100000);
    const double start[4] = {0.0, 1.0, 1.0, -0.5};
    std::copy(start, start + n, ode->data(Buffer::State));
    ode->reset(0.0);
    ode->setRoots(2, &oscillatorRoots);
    ode->setStopTime(2.5);
  }
  const auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  double tOwn = 0, tRef = 0;
  int roots = 0, stops = 0;
  while (tOwn < 6.0) {
    const double tPrev = tOwn;
    const StepEnd endOwn = own.step(tOwn + 1.0, Buffer::State, tOwn);
    const StepEnd endRef = ref.step(tRef + 1.0, Buffer::State, tRef);
    ASSERT_EQ(endOwn, endRef);
    ASSERT_TRUE(same(tOwn, tRef)) << tOwn << " " << tRef;
    ASSERT_TRUE(same(own.currentStep(), ref.currentStep()));
    for (int j = 0; j < n; ++j)
      ASSERT_TRUE(same(own.data(Buffer::State)[j], ref.data(Buffer::State)[j])) << tOwn;
    if (endOwn == StepEnd::Root) {
      ++roots;
      int foundOwn[2], foundRef[2];
      own.rootsFound(foundOwn);
      ref.rootsFound(foundRef);
      EXPECT_EQ(foundOwn[0], foundRef[0]);
      EXPECT_EQ(foundOwn[1], foundRef[1]);
    }
    // Between the last two returns (within the last step), ARKODE's
    // interpolant.
    own.interpolate(0.5 * (tPrev + tOwn), Buffer::Scratch);
    ref.interpolate(0.5 * (tPrev + tOwn), Buffer::Scratch);
    for (int j = 0; j < n; ++j)
      ASSERT_TRUE(same(own.data(Buffer::Scratch)[j], ref.data(Buffer::Scratch)[j]));
    if (endOwn == StepEnd::StopTime) {
      // A reset there with an initial step, as the arena makes them.
      ++stops;
      for (Integrator* ode : {&own, &ref}) {
        ode->data(Buffer::State)[1] += 0.125;
        ode->reset(tOwn);
        ode->setInitStep(0.01);
      }
    }
  }
  EXPECT_GE(roots, 3);
  EXPECT_EQ(stops, 1);
  EXPECT_EQ(own.steps(), ref.steps());
  EXPECT_EQ(own.rhsEvals(), ref.rhsEvals());
}

// Four values (the arena's two robots) take arkode.cpp's four-value path,
// two (one robot) the general one.
TEST(Arkode, OwnVectorOperationsGiveSundialsBitsExactly) {
  compareWithSundials(4);
  compareWithSundials(2);
}

// A call ARKODE refuses (a negative tolerance is ARK_ILL_INPUT) throws
// SolverError naming the SUNDIALS function and its flag.
TEST(Arkode, ARefusedCallThrowsSolverErrorNamingTheFunction) {
  Fixture f;
  try {
    f.ode.setTolerances(-1.0, 1e-10);
    FAIL() << "no SolverError";
  } catch (const SolverError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("SUNDIALS: ", 0), 0u) << what;
    EXPECT_NE(what.find("SStolerances failed, flag -"), std::string::npos) << what;
  }
}

}  // namespace
