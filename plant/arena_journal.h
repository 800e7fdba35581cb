// plant/arena_journal.h -- internal: the calls that changed an arena since
// its last checkpoint, kept so that a copy of it can be made by restoring
// the checkpoint and making them again (Arena's copy constructor,
// arena_journal.cpp). SUNDIALS keeps its integrator's state private, but
// where the arena has just reset ARKODE and not stepped since, the
// arena's own state (ArenaState, arena_impl.h) and the reset's arguments
// are all there is: a checkpoint. Between checkpoints an arena's state
// depends on nothing but the calls that changed it and the random words
// they drew (arena.cpp, "Stepping": not on queries, nor on how the caller
// chops time). A journal lasts from one checkpoint to the next; marks keep
// theirs alive, so memory follows the marks, not the run's length.
#pragma once
#include <cstdint>
#include <exception>
#include <memory>
#include <vector>

#include "plant/plant.h"

namespace simbot::plant::arena_detail {

struct Checkpoint;  // arena_impl.h

struct Journal {
  enum class Kind : std::uint8_t {
    SetWheels,
    SetDrive,
    SetPortB,
    TriggerReflex,
    EdgeHandlerEntered,
    SetSupply,
    Advance,
    Retreat
  };
  struct Call {
    Kind kind;
    int robot = 0;
    std::int64_t tick = 0;
    MotorFrame frame{};
    double left = 0, right = 0;
    std::uint8_t value = 0;
    Bumper side = Bumper::Front;
    bool gunLuck = false, muzzle = false, dispersion = false;  // setPortB was given the stream
  };
  // The random words setPortB's calls drew, in order, each with its stream
  // (0: gunLuck, 1: muzzle, 2: dispersion).
  struct Draw {
    std::uint8_t stream;
    std::uint64_t bits;
  };

  Journal(std::shared_ptr<const ArenaConfig> config, std::shared_ptr<const Checkpoint> from)
      : initial(std::move(config)), base(std::move(from)) {}
  std::shared_ptr<const ArenaConfig> initial;  // the configuration the arena was made with
  std::shared_ptr<const Checkpoint> base;      // where the calls start (null: construction)
  std::vector<Call> calls;
  std::vector<Draw> draws;

  // Kept for the duration of one public call: the call is in the journal,
  // and taken out again (with its draws) if the call throws.
  class Entry {
   public:
    // Inline: a normal run keeps no journal, and pays one test a call.
    Entry(Journal* journal, const Call& call) : journal_(journal) {
      if (journal_) open(call);
    }
    ~Entry() {
      if (journal_) close();
    }
    Entry(const Entry&) = delete;
    Entry& operator=(const Entry&) = delete;

   private:
    void open(const Call& call);
    void close();
    Journal* journal_;
    std::size_t draws_ = 0;
    int exceptions_ = 0;
  };

  // A stream whose words go to the journal as they are drawn.
  class Recorder final : public RandomBits {
   public:
    Recorder(Journal* journal, RandomBits* source, std::uint8_t stream)
        : journal_(journal), source_(source), stream_(stream) {}
    std::uint64_t next() override;
    // The stream to hand on: the recorder while journaling, else the source.
    RandomBits* use() { return journal_ && source_ ? this : source_; }

   private:
    Journal* journal_;
    RandomBits* source_;
    std::uint8_t stream_;
  };

  // Makes every call again on `arena` (new, of configuration `initial`).
  // The first `calls` calls and `draws` draws (all: the whole journal).
  void replay(Arena& arena, std::size_t callCount = SIZE_MAX,
              std::size_t drawCount = SIZE_MAX) const;
};

}  // namespace simbot::plant::arena_detail
