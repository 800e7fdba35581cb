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
  if (impl_->journal) return;
  if (impl_->now != 0 || impl_->segTick != 0)
    throw std::logic_error("an arena keeps its journal from its first call");
  impl_->journal = std::make_shared<arena_detail::Journal>(impl_->cfg);
}

Arena::Mark Arena::mark() const {
  const auto& journal = impl_->journal;
  if (!journal) throw std::logic_error("an arena is marked only when it keeps its journal");
  return Mark{journal, journal->calls.size(), journal->draws.size()};
}

Arena::Arena(const Mark& mark) {
  impl_ = std::make_unique<Impl>(mark.journal->initial);
  keepJournal();
  mark.journal->replay(*this, mark.calls, mark.draws);
}

Arena::Arena(const Arena& other) {
  const arena_detail::Journal* journal = other.impl_->journal.get();
  if (!journal) throw std::logic_error("an arena is copied only when it keeps its journal");
  impl_ = std::make_unique<Impl>(journal->initial);
  keepJournal();
  journal->replay(*this);
}

Arena& Arena::operator=(const Arena& other) {
  if (this != &other) {
    Arena copy(other);
    impl_ = std::move(copy.impl_);
  }
  return *this;
}

}  // namespace simbot::plant
