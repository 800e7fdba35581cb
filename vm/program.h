// The constant half of a VM (as MuJoCo keeps mjModel apart from mjData):
// what is decoded once from an image and a cost table and never changes
// while the program runs. A Program is shared read-only, through
// std::shared_ptr<const Program>, by a VM and every copy of it (a
// debugger's snapshots), which hold only the machine's state (state.h).
// Not part of the VM's interface (vm.h): nothing outside vm/ includes it.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "vm/cost.h"
#include "vm/image.h"
#include "vm/superinstructions.h"

namespace simbot::vm::detail {

class Dispatch;

// The fast path's entry for one code address (vm.cpp "Fast path"): the
// handler's label, the opcode's cost (0 for kTrap) and the opcode.
struct Fast {
  const void* label;
  uint32_t cost;
  uint8_t op;
};

// The labels of run<kProfile>'s handlers, known only inside it.
struct Labels {
  const void* const* op;     // per opcode, kTrap's last
  const void* longOp;        // an instruction longer than kMaxStepTstates
  const void* const* super;  // per superinstruction; null: none fused
};

struct Program {
  Program(const Image& image, const CostTable& costs);
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  // In `ops`, where the slow path must look first (an invalid opcode, an
  // instruction that runs past the end of the code or jumps outside it, a
  // fast-forward loop top, a breakpoint); kCodePad of them past the end.
  static constexpr uint8_t kTrap = kOpCount;
  static constexpr uint32_t kCodePad = 8;

  const Image* image;  // not owned: it outlives every VM that runs it
  CostTable costs;
  // The code with kCodePad zero bytes after it, for operands.
  std::vector<uint8_t> padded;
  // Where a smashed return address may lead: instruction starts.
  std::vector<uint8_t> instructionStart;
  // Per RET, the auto frame it releases, or -1 (Image::returnFrames).
  std::vector<int32_t> returnFrame;
  // Per IM2 vector byte, the #INT_VEC handler's address, or -1.
  std::array<int32_t, 256> handlerFor{};
  // Delay loops fast-forward runs (fast_forward.cpp), and per code byte
  // the index of the loop whose top it is, or -1 (empty: none).
  static constexpr uint32_t kMaxLoopBytes = 32;
  struct Loop {
    uint32_t top, exit, counter;
    uint32_t limit;
    bool wide;       // a long counter
    bool isSigned;   // LTW, LEW, LTL, LEL
    bool inclusive;  // <=
    // Worked out once from the above (findLoops), not at every arrival:
    // the last counter number the compare holds for, below the top of the
    // counter's range (it never wraps in fast-forward), and whether the
    // limit is non-negative or unsigned (a signed compare's regime).
    int64_t last = 0;
    bool limitInRegime = false;
    // A counter value as a signed or unsigned number of the counter's width.
    int64_t number(uint32_t x) const {
      if (!isSigned) return wide ? int64_t{x} : int64_t{x & 0xFFFFu};
      return wide ? static_cast<int32_t>(x) : static_cast<int16_t>(x);
    }
  };
  std::vector<Loop> loops;
  std::vector<int16_t> loopAtTop;
  // Per superinstruction, the most ticks its inner boundaries can lie after
  // its first piece's dispatch (every piece at its slowest path; the
  // boundary after the last is not inner, but a long last piece's steps
  // are), under the cost table: when they all lie before the limit,
  // nothing can happen at them (vm.cpp State::superinstruction).
  std::array<uint32_t, kSuperCount> superSpan{};
  // Per superinstruction and piece k, what the pieces after k cost on their
  // not-taken paths ([0]: all but the first).
  std::array<std::array<uint32_t, kMaxPieces>, kSuperCount> superAfter{};
  // The dispatch without breakpoints.
  std::shared_ptr<const Dispatch> plain;

  // A REL16 instruction's target, from its start (in the padded code).
  int64_t relTargetAt(uint32_t address) const;

 private:
  void findLoops();
  std::vector<uint8_t> decode() const;
  void setSuperSpans();
};

// What the dispatch loop runs: per code address the opcode, or kTrap,
// with a VM's breakpoints trapped. The program's own (Program::plain) has
// none; a VM that sets one makes its own copy, which its snapshots share
// until its breakpoints change again (Vm::setBreakpoint), so that a
// snapshot copies no table.
class Dispatch {
 public:
  // `breakpoints`: one flag per code byte and one past the end, or empty.
  Dispatch(const Program& program, std::vector<uint8_t> ops, std::vector<uint8_t> breakpoints);
  Dispatch(const Dispatch&) = delete;
  Dispatch& operator=(const Dispatch&) = delete;
  // This dispatch with a breakpoint at `address` set or cleared.
  std::shared_ptr<const Dispatch> withBreakpoint(const Program& program, uint32_t address,
                                                 bool enabled) const;

  const std::vector<uint8_t>& ops() const { return ops_; }
  const std::vector<uint8_t>& breakpoints() const { return breakpoints_; }
  bool anyBreakpoint() const { return anyBreakpoint_; }
  bool breakpointAt(uint32_t address) const {
    return address < breakpoints_.size() && breakpoints_[address];
  }
  // Per Program::loops: a breakpoint inside turns its fast-forward off.
  bool breakpointInLoop(size_t loop) const { return loopBreak_[loop] != 0; }
  // The superinstruction whose pieces start at `address` (each where the
  // one before leads, all ordinary and none a trap here), or -1.
  int superinstructionAt(const Program& program, uint32_t address) const;
  // The fast path's table of run<kProfile> (k = 1 when profiling), built
  // at the first run of each kind (the labels are known only inside run())
  // and shared by every VM that runs this dispatch.
  const Fast* fast(int k, const Program& program, const Labels& labels) const {
    if (const Fast* f = built_[static_cast<size_t>(k)].load(std::memory_order_acquire)) return f;
    return build(k, program, labels);
  }

 private:
  const Fast* build(int k, const Program& program, const Labels& labels) const;

  std::vector<uint8_t> ops_;
  std::vector<uint8_t> breakpoints_;
  std::vector<uint8_t> loopBreak_;
  bool anyBreakpoint_ = false;
  mutable std::mutex building_;
  mutable std::array<std::vector<Fast>, 2> fast_;
  mutable std::array<std::atomic<const Fast*>, 2> built_{};
};

}  // namespace simbot::vm::detail
