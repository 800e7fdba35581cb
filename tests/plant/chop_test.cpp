// The plant's results must not depend on how the caller chops time into
// advance() calls: the same inputs at the same ticks give bit-identical
// states, the same events at the same ticks and the same integrator work,
// whether advance() is called every 9,600 ticks (the scheduler's largest
// round), only at the input ticks, or at irregular ticks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "plant_support.h"

namespace {

using namespace plant_test;

struct Input {
  std::int64_t tick;
  int robot;
  bool wheels;  // setWheels(frame) or setPortB(portB)
  const char* frame;
  std::uint8_t portB;
};

struct Logged {
  std::int64_t tick;
  Event event;
};

struct ChopRun {
  std::vector<double> samples;  // per sample tick and robot: pose, wheels, eyes
  std::vector<Logged> events;
  IntegratorStats stats;
  int advances = 0;
  int overshoots = 0;  // advances past an input that were retreated from
};

constexpr std::int64_t kEnd = 30 * kTicksPerSecond + 4321;
constexpr std::int64_t kSampleEvery = 23'456;

std::vector<Input> script() {
  // Robot A: gun motor 1 (bit 3), solenoid 1 (bit 4). Robot B: gun motor 2
  // (bit 7), solenoid 2 (bit 5). Ticks deliberately off any 9,600 grid.
  std::vector<Input> in = {
      {0, 0, false, nullptr, 0x08},
      {0, 1, false, nullptr, 0x80},
      {0, 0, true, "ffg0cfg0", 0},
      {3'337'771, 1, true, "8rg08fg0", 0},
      {9'216'007, 0, false, nullptr, 0x18},  // A fires
      {9'400'013, 0, false, nullptr, 0x08},
      {12'000'001, 1, false, nullptr, 0xa0},  // B fires
      {12'345'679, 1, false, nullptr, 0x80},
      {14'000'003, 0, true, "ffg0ffg0", 0},
      {23'456'789, 1, true, "ffg0ffg0", 0},
      {41'000'017, 0, true, "3fg0frg0", 0},
      {41'000'017, 1, true, "frg0ffg0", 0},
      {55'555'553, 0, true, "ffg0ffg0", 0},
      {61'234'567, 0, false, nullptr, 0x18},  // A fires again
      {61'500'011, 0, false, nullptr, 0x08},
      {77'777'777, 1, true, "cfg0ffg0", 0},
      {99'999'989, 0, true, "frg0frg0", 0},
      {130'000'027, 1, true, "ffg0ffs0", 0},
      {150'000'001, 0, true, "afg0ffg0", 0},
      {180'000'019, 1, true, "ffg0ffg0", 0},
      {200'000'003, 1, false, nullptr, 0xa0},  // B fires again
      {200'300'007, 1, false, nullptr, 0x80},
      {230'000'011, 0, true, "ffg0ffg0", 0},
  };
  return in;
}

// Drives one arena through the script; `nextStop(now, target)` says where
// the next advance() stops (at most target). With `copyAfter` >= 0 the
// arena keeps its journal and, after that many inputs, the run goes on with
// a copy of it (the original is dropped); with `draws` the gun strokes draw
// jams, misfires and muzzle speeds from seeded streams.
// With `overshoot` > 0, before each input the arena is first advanced up
// to that many ticks past the input's tick and then retreated to it, as the
// scheduler does when a robot's action lands before the horizon it ran the
// plant to (what that advance reported is dropped: it never happened).
ChopRun drive(const std::function<std::int64_t(std::int64_t, std::int64_t)>& nextStop,
              int copyAfter = -1, bool draws = false, std::int64_t overshoot = 0) {
  const Profile p = defaults();
  auto owned = std::make_unique<Arena>(makeArenaConfig(p, 2));
  if (copyAfter >= 0) owned->keepJournal();
  SplitMix64 gunLuck(7), muzzle(8);
  ChopRun run;
  int inputs = 0;
  std::int64_t nextSample = 0;
  auto sample = [&] {
    const Arena& a = *owned;
    for (; nextSample <= a.now(); nextSample += kSampleEvery) {
      // Nothing before the last re-initialisation was left unsampled.
      EXPECT_GE(nextSample, a.lastReinitTick());
      for (int r = 0; r < 2; ++r) {
        const RobotState s = a.state(r, nextSample);
        const EyeReadings e = a.eyeReadings(r, nextSample);
        run.samples.insert(run.samples.end(),
                           {s.pose.x_ft, s.pose.y_ft, s.pose.heading_deg, s.left_fps, s.right_fps,
                            s.odometer_ft, s.gun_wheel[0], s.gun_wheel[1],
                            static_cast<double>(e.left), static_cast<double>(e.right)});
      }
    }
  };
  auto advanceTo = [&](std::int64_t target) {
    Arena& a = *owned;
    while (a.now() < target) {
      const std::int64_t stop = nextStop(a.now(), target);
      const AdvanceResult r = a.advance(stop);
      ++run.advances;
      EXPECT_LE(r.tick, stop);
      EXPECT_EQ(r.tick, a.now());
      for (const Event& e : r.events) run.events.push_back({r.tick, e});
      sample();
    }
  };
  sample();
  for (const Input& in : script()) {
    if (inputs++ == copyAfter) {
      auto copy = std::make_unique<Arena>(*owned);
      owned = std::move(copy);
    }
    Arena& a = *owned;
    advanceTo(in.tick);
    if (overshoot > 0 && in.tick > 0) {
      if (a.advance(in.tick + overshoot).tick > in.tick) ++run.overshoots;
      a.retreat(in.tick);
    }
    if (in.wheels) {
      a.setWheels(in.robot, frame(in.frame), in.tick);
    } else {
      for (const Event& e : a.setPortB(in.robot, in.portB, in.tick, draws ? &gunLuck : nullptr,
                                       draws ? &muzzle : nullptr))
        run.events.push_back({in.tick, e});
    }
  }
  advanceTo(kEnd);
  run.stats = owned->stats();
  return run;
}

bool sameEvent(const Logged& x, const Logged& y) {
  const Event& a = x.event;
  const Event& b = y.event;
  return x.tick == y.tick && a.kind == b.kind && a.robot == b.robot && a.other == b.other &&
         a.detector == b.detector && a.bumper == b.bumper && a.with == b.with && a.miss == b.miss &&
         a.gun == b.gun && a.ball == b.ball;
}

void expectSame(const ChopRun& x, const ChopRun& y, const char* what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(x.samples.size(), y.samples.size());
  EXPECT_EQ(std::memcmp(x.samples.data(), y.samples.data(), x.samples.size() * sizeof(double)), 0);
  for (std::size_t i = 0; i < x.samples.size(); ++i)
    if (std::memcmp(&x.samples[i], &y.samples[i], sizeof(double)) != 0) {
      ADD_FAILURE() << "first differing sample value " << i << ": " << x.samples[i] << " vs "
                    << y.samples[i];
      break;
    }
  ASSERT_EQ(x.events.size(), y.events.size());
  for (std::size_t i = 0; i < x.events.size(); ++i)
    EXPECT_TRUE(sameEvent(x.events[i], y.events[i]))
        << "event " << i << ": " << eventKindName(x.events[i].event.kind) << " at "
        << x.events[i].tick << " vs " << eventKindName(y.events[i].event.kind) << " at "
        << y.events[i].tick;
  EXPECT_EQ(x.stats.steps, y.stats.steps);
  EXPECT_EQ(x.stats.rhs_evals, y.stats.rhs_evals);
  EXPECT_EQ(x.stats.reinits, y.stats.reinits);
  EXPECT_EQ(x.stats.roots, y.stats.roots);
}

TEST(Chopping, ResultsDoNotDependOnWhereAdvanceStops) {
  constexpr std::int64_t kRound = 9'600;
  const ChopRun rounds = drive([](std::int64_t now, std::int64_t target) {
    return std::min(target, (now / kRound + 1) * kRound);
  });
  const ChopRun atInputs = drive([](std::int64_t, std::int64_t target) { return target; });
  SplitMix64 rng(12345);
  const ChopRun irregular = drive([&rng](std::int64_t now, std::int64_t target) {
    return std::min(target, now + 1 + static_cast<std::int64_t>(rng.next() % 300'000));
  });

  // The scenario exercises what chopping could disturb.
  auto count = [&](EventKind k) {
    return std::count_if(atInputs.events.begin(), atInputs.events.end(),
                         [k](const Logged& l) { return l.event.kind == k; });
  };
  EXPECT_GT(count(EventKind::EdgeEnter), 0);
  EXPECT_GT(count(EventKind::BallLaunch), 0);
  EXPECT_GT(count(EventKind::BallHit) + count(EventKind::BallMiss), 0);
  EXPECT_GT(count(EventKind::ReflexStart), 0);
  EXPECT_GT(rounds.advances, 10 * atInputs.advances);
  EXPECT_GT(atInputs.samples.size(), 20'000u);

  expectSame(atInputs, rounds, "every 9,600 ticks vs only at inputs");
  expectSame(atInputs, irregular, "irregular stops vs only at inputs");
}

// Steps that ARKODE took past an input's tick before the input came (the
// advance overshot it and was retreated) leave nothing behind: a reset
// starts from the step planned where the input is, with the step
// controller's error history cleared, so the run is bit-identical to one
// that never went past the input. (ARKODE's reset alone keeps the history:
// the runs then differ in the last bits, seen as a trace that changed with
// fast-forward on.)
TEST(Chopping, StepsPastAnInputTheArenaRetreatedFromLeaveNoTrace) {
  const auto atInputs = [](std::int64_t, std::int64_t target) { return target; };
  const ChopRun direct = drive(atInputs);
  for (const std::int64_t overshoot : {4'321, 96'000, 700'001}) {
    ChopRun probed = drive(atInputs, -1, false, overshoot);
    EXPECT_GT(probed.overshoots, 10);  // most inputs: the advance went past them
    // The integrator's work includes the steps past each input and the
    // roots found there.
    probed.stats.steps = direct.stats.steps;
    probed.stats.rhs_evals = direct.stats.rhs_evals;
    probed.stats.roots = direct.stats.roots;
    expectSame(direct, probed,
               ("advanced past each input by " + std::to_string(overshoot)).c_str());
  }
  // And with irregular stops between the inputs.
  SplitMix64 rng(777);
  ChopRun both = drive(
      [&rng](std::int64_t now, std::int64_t target) {
        return std::min(target, now + 1 + static_cast<std::int64_t>(rng.next() % 300'000));
      },
      -1, false, 96'000);
  EXPECT_GT(both.overshoots, 10);
  both.stats.steps = direct.stats.steps;
  both.stats.rhs_evals = direct.stats.rhs_evals;
  both.stats.roots = direct.stats.roots;
  expectSame(direct, both, "irregular stops, and past each input by 96,000");
}

// A copy of an arena (made by replaying its journal) goes on exactly as
// the arena would have: copied after 5 inputs (A has fired; the ball is in
// flight), after 13 (mid-match) or after all, with every stroke's random
// draws, it gives the bit-identical run, events and integrator work.
TEST(ArenaCopy, GoesOnAsTheOriginalWould) {
  const auto atInputs = [](std::int64_t, std::int64_t target) { return target; };
  const ChopRun original = drive(atInputs, -1, true);
  for (const int after : {0, 5, 13, static_cast<int>(script().size()) - 1}) {
    const ChopRun copied = drive(atInputs, after, true);
    expectSame(original, copied, ("copied after input " + std::to_string(after)).c_str());
  }
  // The same with the scheduler's rounds, which retreat and re-advance.
  constexpr std::int64_t kRound = 9'600;
  const auto rounds = [](std::int64_t now, std::int64_t target) {
    return std::min(target, (now / kRound + 1) * kRound);
  };
  expectSame(drive(rounds, -1, true), drive(rounds, 9, true), "rounds, copied after input 9");
}

// A copy is a checkpoint restored and the calls since it made again: one
// is taken where an input has just reset ARKODE, so after every input a
// copy goes on as the original would (run, events and integrator work, bit
// for bit), and in a long run the calls to make again stay those since the
// last input, not the run's. Here 240 s of frames a second apart, 960
// rounds a second (230,400 advances): a mark's journal holds a second's 960
// advances and the frame, or two seconds' where a frame reset nothing (the
// bumper reflex held the wheels: 3 of the 240 here); never more.
TEST(ArenaCopy, ReplaysOnlyTheCallsSinceTheLastReset) {
  constexpr std::int64_t kRound = 9'600;
  const auto rounds = [](std::int64_t now, std::int64_t target) {
    return std::min(target, (now / kRound + 1) * kRound);
  };
  const ChopRun original = drive(rounds, -1, true);
  for (int after = 0; after < static_cast<int>(script().size()); ++after)
    expectSame(original, drive(rounds, after, true),
               ("rounds, copied after input " + std::to_string(after)).c_str());

  Arena a(makeArenaConfig(defaults(), 2));
  a.keepJournal();
  const char* frames[] = {"ffg0ffg0", "frg0ffg0", "ffg0frg0", "afg0afg0"};
  std::size_t most = 0;
  for (int second = 0; second < 240; ++second) {
    const std::int64_t at = second * kTicksPerSecond;
    while (a.now() < at) a.advance(rounds(a.now(), at));
    a.setWheels(second % 2, frame(frames[second % 4]), at);
    most = std::max(most, a.mark().calls);
  }
  EXPECT_LE(most, 2u * 970u);
  EXPECT_GE(most, 961u);  // a second's calls at least: the test sees what it bounds
}

// An arena that did not keep its journal cannot be copied, nor can one that
// starts keeping it after its first call.
TEST(ArenaCopy, NeedsTheJournalFromTheFirstCall) {
  Arena a(makeArenaConfig(defaults(), 2));
  EXPECT_THROW(Arena{a}, std::logic_error);
  a.advance(1000);
  EXPECT_THROW(a.keepJournal(), std::logic_error);
}

}  // namespace
