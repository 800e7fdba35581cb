// plant/arena_journal.cpp -- an arena copied by making its calls again
// (arena_journal.h).
#include "plant/arena_journal.h"

#include <stdexcept>

#include "plant/arena_impl.h"

namespace simbot::plant {

namespace arena_detail {

void Journal::Entry::open(const Call& call) {
  exceptions_ = std::uncaught_exceptions();
  draws_ = journal_->draws.size();
  journal_->calls.push_back(call);
}

void Journal::Entry::close() {
  if (std::uncaught_exceptions() == exceptions_) return;
  journal_->calls.pop_back();
  journal_->draws.resize(draws_);
}

std::uint64_t Journal::Recorder::next() {
  const std::uint64_t bits = source_->next();
  journal_->draws.push_back({stream_, bits});
  return bits;
}

namespace {

// The words a call drew, handed back in the order it drew them.
class Replayed final : public RandomBits {
 public:
  Replayed(const std::vector<Journal::Draw>& draws, std::size_t& cursor, std::uint8_t stream)
      : draws_(draws), cursor_(cursor), stream_(stream) {}
  std::uint64_t next() override {
    if (cursor_ >= draws_.size() || draws_[cursor_].stream != stream_)
      throw std::logic_error("an arena's replay drew other words than the arena did");
    return draws_[cursor_++].bits;
  }

 private:
  const std::vector<Journal::Draw>& draws_;
  std::size_t& cursor_;
  std::uint8_t stream_;
};

}  // namespace

void Journal::replay(Arena& arena, std::size_t callCount, std::size_t drawCount) const {
  callCount = std::min(callCount, calls.size());
  drawCount = std::min(drawCount, draws.size());
  std::size_t cursor = 0;
  Replayed gunLuck(draws, cursor, 0), muzzle(draws, cursor, 1), dispersion(draws, cursor, 2);
  for (std::size_t k = 0; k < callCount; ++k) {
    const Call& c = calls[k];
    switch (c.kind) {
      case Kind::SetWheels:
        arena.setWheels(c.robot, c.frame, c.tick);
        break;
      case Kind::SetDrive:
        arena.setDrive(c.robot, c.left, c.right, c.tick);
        break;
      case Kind::SetPortB:
        arena.setPortB(c.robot, c.value, c.tick, c.gunLuck ? &gunLuck : nullptr,
                       c.muzzle ? &muzzle : nullptr, c.dispersion ? &dispersion : nullptr);
        break;
      case Kind::TriggerReflex:
        arena.triggerReflex(c.robot, c.side, c.tick);
        break;
      case Kind::EdgeHandlerEntered:
        arena.edgeHandlerEntered(c.robot, c.tick);
        break;
      case Kind::SetSupply:
        arena.setSupply(c.robot, c.left, c.tick);
        break;
      case Kind::Advance:
        arena.advance(c.tick);
        break;
      case Kind::Retreat:
        arena.retreat(c.tick);
        break;
    }
  }
  if (cursor != drawCount)
    throw std::logic_error("an arena's replay drew fewer words than the arena did");
}

}  // namespace arena_detail

void Arena::keepJournal() {
  Impl& m = *impl_;
  if (m.journal) return;
  if (m.now != 0 || m.segTick != 0)
    throw std::logic_error("an arena keeps its journal from its first call");
  m.sharedCfg = std::make_shared<const ArenaConfig>(m.cfg);
  m.journal = std::make_shared<arena_detail::Journal>(m.sharedCfg, nullptr);
}

Journal::Entry Arena::Impl::enter(const Journal::Call& call) {
  // Only while ARKODE has just been reset; and not before its first step
  // (its first step's growth limit is another than after a reset: restore()
  // gives a new integrator one step) nor with a root's flag carried over.
  if (journal && fresh && reinitSerial != checkpointSerial && !rootFlagCarried &&
      arenaSteps() > 0) {
    auto cp = std::make_shared<const Checkpoint>(
        Checkpoint{static_cast<const ArenaState&>(*this), arenaSteps(), arenaRhsEvals()});
    journal = std::make_shared<Journal>(sharedCfg, std::move(cp));
    checkpointSerial = reinitSerial;
  }
  return Journal::Entry(journal.get(), call);
}

// A new integrator differs from one that has been reset in one way that
// matters: ARKODE bounds the growth of the first step it ever takes by
// another factor (etamx1) than a later one's after a reset. So the new one
// takes one step first (from the configuration's start; whatever it
// computes is overwritten), then gets the checkpoint's reset: its start
// (segY's centres at segT0), initial step, maximum step, root functions
// and stop time, as reinit() gave them to the original.
void Arena::Impl::restore(const Checkpoint& cp) {
  double tr = 0;
  ode.step(kFirstStepHorizon, ark::Buffer::Scratch, tr);
  static_cast<ArenaState&>(*this) = cp.state;
  rootRawValid = false;  // (the step above evaluated the new integrator's roots)
  centresOf(segY.data(), ode.data(ark::Buffer::State));
  ode.reset(segT0);
  ode.setInitStep(recs.front().next);
  ode.setMaxStep(maxStepSet);
  if (nRootsRegistered >= 0) ode.setRoots(nRootsRegistered, &Impl::rootThunk);
  if (launchStop >= 0) ode.setStopTime(secondsFromTick(launchStop));
  stepsOffset = cp.steps - ode.steps();
  rhsEvalsOffset = cp.rhsEvals - ode.rhsEvals();
  rootFlagCarried = false;
  checkpointSerial = reinitSerial;
  refreshBlockShapes(D);  // contact.h's copies of the blocks (not in the state)
}

Arena::Mark Arena::mark() const {
  const auto& journal = impl_->journal;
  if (!journal) throw std::logic_error("an arena is marked only when it keeps its journal");
  return Mark{journal, journal->calls.size(), journal->draws.size()};
}

// The arena a mark names: the checkpoint its journal starts from restored
// (or a new arena), and the journal's calls up to the mark made again, into
// a journal of its own that starts from the same checkpoint.
Arena::Arena(const Mark& mark) {
  if (!mark.journal) throw std::logic_error("an arena is made from a mark of an arena");
  impl_ = std::make_unique<Impl>(*mark.journal->initial);
  impl_->sharedCfg = mark.journal->initial;
  if (mark.journal->base) impl_->restore(*mark.journal->base);
  impl_->journal = std::make_shared<arena_detail::Journal>(impl_->sharedCfg, mark.journal->base);
  mark.journal->replay(*this, mark.calls, mark.draws);
}

Arena::Arena(const Arena& other)
    : Arena(other.impl_->journal
                ? other.mark()
                : throw std::logic_error("an arena is copied only when it keeps its journal")) {}

Arena& Arena::operator=(const Arena& other) {
  if (this != &other) {
    Arena copy(other);
    impl_ = std::move(copy.impl_);
  }
  return *this;
}

}  // namespace simbot::plant
