// The match's result, once its last round is over: each robot's figures
// (hits, shots, clocks, interrupts, final pose), the warnings, the winner,
// and the trace's closing records.
#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "scheduler/match_impl.h"

namespace simbot::scheduler::detail {

void Match::finish(MatchResult& result) {
  result.rounds = rounds_;
  result.warnings = warnings_;
  for (size_t k = 0; k < fired_.size(); ++k) {
    if (fired_[k]) continue;
    const Injection& in = config_.injections[k];
    const RobotSpec& robot = config_.robots[static_cast<size_t>(in.robot)];
    result.warnings.push_back(
        in.line > 0
            ? fmt::format("--inject {} never fired: {} of {} ran {} time(s) before the run ended",
                          in.text,
                          in.pass ? "the loop on line " + std::to_string(in.line)
                                  : "line " + std::to_string(in.line),
                          robot.program, hitsAt(in, injectionAddress_[k]))
            : fmt::format("--inject {} never fired: the run ended at {:.6f} s", in.text,
                          timebase::secondsFromTicks(result.endTick)));
  }
  result.integrator = arena_.stats();
  for (auto& r : robots_) {
    RobotResult rr = r->result;
    const size_t at = static_cast<size_t>(r->index);
    rr.hits = arena_.hits(r->index) - unscoredHits_[at];
    if (arenaConfig_->referee.judge_scatter) rr.scatterShots = scatterShots_[at];
    rr.shots = arena_.shots(r->index);
    // A secondary weapon's shots and hits, apart from the guns' (the
    // winner is decided on the guns' hits).
    const plant::SecondaryKind secondary =
        arenaConfig_->robots[static_cast<size_t>(r->index)].hardware.secondary.kind;
    if (secondary != plant::SecondaryKind::None)
      rr.secondary = SecondaryResult{plant::secondaryKindName(secondary),
                                     arena_.discShots(r->index), arena_.discHits(r->index)};
    for (const plant::Deployed& item : arena_.deployed())
      if (item.robot == r->index) ++rr.deployed[static_cast<size_t>(item.kind)];
    rr.blockPushFt = arena_.blockPushedFt(r->index);
    // The clock at main's return, or at the end of the run: a VM's clock
    // runs on to the last round's horizon after main returns, and may stand
    // one instruction past the end.
    rr.cycles = static_cast<uint64_t>(rr.exited ? rr.exitTick : std::min(r->now(), result.endTick));
    // A halted VM idles to whichever horizon ended its last run, which
    // depends on how long the rounds were (a solo run that stops at main's
    // return ends before it): what the profile counts ends at the later of
    // its halt and the end of the run.
    rr.vmClock = static_cast<uint64_t>(
        r->vm().halted() ? std::min(r->now(), std::max(r->vm().haltedSince(), result.endTick))
                         : r->now());
    rr.vmInstructions = r->vm().stats().instructions;
    rr.vmFastForwarded = r->vm().stats().fastForwarded;
    if (config_.profile) {
      rr.profile = r->vm().profile();
      rr.serialIsrCycles = r->vm().serialIsrCycles();
      rr.timerIsrCycles = r->vm().timerIsrCycles();
    }
    for (vm::Irq irq : {vm::Irq::Pio, vm::Irq::Timer, vm::Irq::SerialTx})
      rr.interrupts[std::string(vm::irqName(irq))] +=
          r->board.interruptCounts[static_cast<size_t>(irq)];
    if (r->battery) rr.batteryVFinal = r->battery->voltage(result.endTick);
    // After a plant fault the plant answers only from its last re-initialisation.
    rr.finalPose =
        arena_.pose(r->index, std::clamp(result.endTick, arena_.lastReinitTick(), arena_.now()));
    result.robots.push_back(std::move(rr));
  }
  if (result.robots.size() == 2) {
    const int a = result.robots[0].hits, b = result.robots[1].hits;
    const bool faultA = result.robots[0].fault.has_value();
    const bool faultB = result.robots[1].fault.has_value();
    if (a != b) {
      result.winner = a > b ? "A" : "B";
    } else if (faultA != faultB) {
      result.winner = faultA ? "B" : "A";  // a robot that faulted loses a tied round
    } else {
      result.tieBrokenByCoin = true;
      result.winner = (coin_.next() >> 63) ? "B" : "A";
    }
  }
  if (trace_.on()) {
    for (const auto& rr : result.robots) {
      const int i = &rr - result.robots.data();
      emit(result.endTick,
           trace::rec::RobotResult{i, rr.hits, rr.shots, rr.framesLatched, rr.framesRejected,
                                   rr.framesOverwritten, static_cast<int64_t>(rr.cycles),
                                   rr.fault.has_value(), rr.reloads, rr.exited},
           {});
      if (rr.secondary)
        emit(result.endTick,
             trace::rec::SecondaryResult{i, rr.secondary->kind, rr.secondary->shots,
                                         rr.secondary->hits},
             {});
    }
    emit(result.endTick, trace::rec::End{result.winner, result.tieBrokenByCoin}, {});
  }
  trace_.close();
}

}  // namespace simbot::scheduler::detail
