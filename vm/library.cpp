// The VM's library routines: Dynamic C's built-in library (builtins.def) as
// the VM runs it: a call's sequence charged first (in steps when longer than
// one), its effect at the end of it, long routines (strcpy, printf...) one
// unit per step with a boundary between steps; and the firsttime Delay
// functions of costatements.
#include <bit>
#include <cstdio>
#include <cstring>

#include "vm/cost_sums.h"
#include "vm/float_math.h"
#include "vm/state.h"

namespace simbot::vm {

// A firsttime Delay function on the costatement whose CoData is at cd.
bool Vm::State::delayDone(uint32_t cd, int32_t interval, uint32_t timerAddress,
                          uint32_t instructionPc) {
  if (!checkAccess(cd, kCoDataSize, instructionPc)) return false;
  const uint32_t timer = timerAddress ? rd32(timerAddress) : 0;
  if (rd8(cd + kCoFirstTime)) {
    wr8(cd + kCoFirstTime, 0);
    wr32(cd + kCoContent, timer);
  }
  return static_cast<int32_t>(timer - rd32(cd + kCoContent)) >= interval;
}

// ---- library calls -------------------------------------------------------

namespace {

// MATH.LIB: float_math.h's bit-identical functions (y: the second argument).
float mathLib(Lib id, float x, float y) {
  switch (id) {
    case Lib::SQRT:
      return mathSqrt(x);
    case Lib::SIN:
      return mathSin(x);
    case Lib::COS:
      return mathCos(x);
    case Lib::TAN:
      return mathTan(x);
    case Lib::ATAN:
      return mathAtan(x);
    case Lib::ASIN:
      return mathAsin(x);
    case Lib::ACOS:
      return mathAcos(x);
    case Lib::EXP:
      return mathExp(x);
    case Lib::LOG:
      return mathLog(x);
    case Lib::FLOOR:
      return mathFloor(x);
    case Lib::CEIL:
      return mathCeil(x);
    case Lib::ATAN2:
      return mathAtan2(x, y);
    case Lib::POW:
      return mathPow(x, y);
    default:
      return mathFmod(x, y);
  }
}

}  // namespace

std::string Vm::State::formatPrintf(uint32_t instructionPc, int formatArg) {
  std::string out;
  uint32_t f = lib.args[formatArg];
  int next = formatArg + 1;
  auto arg = [&]() -> uint32_t { return next < lib.argc ? lib.args[next++] : 0; };
  auto readString = [&](uint32_t a, size_t limit) {
    std::string s;
    while (s.size() < limit) {
      if (!checkAccess(a, 1, instructionPc)) break;
      char c = static_cast<char>(rd8(a++));
      if (c == 0) break;
      s.push_back(c);
    }
    return s;
  };
  const std::string format = readString(f, 4096);
  char buf[512];
  for (size_t i = 0; i < format.size(); ++i) {
    char c = format[i];
    if (c != '%') {
      out.push_back(c);
      continue;
    }
    // %[flags][width][.precision][l]conv; width and precision are read as
    // numbers and clamped to kMaxPrintfField, as the era's library, which
    // formatted into a small buffer, could not print more.
    std::string spec = "%";
    size_t j = i + 1;
    while (j < format.size() && format[j] != '\0' && std::strchr("-0+ #", format[j]))
      spec.push_back(format[j++]);
    const auto number = [&]() {
      long n = 0;
      while (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j])))
        n = std::min<long>(n * 10 + (format[j++] - '0'), kMaxPrintfField);
      return n;
    };
    if (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j])))
      spec += std::to_string(number());
    if (j < format.size() && format[j] == '.') {
      ++j;
      spec += "." + std::to_string(number());
    }
    bool isLong = false;
    if (j < format.size() && format[j] == 'l') {
      isLong = true;
      ++j;
    }
    if (j >= format.size()) {
      out += format.substr(i);
      break;
    }
    char conv = format[j];
    i = j;
    switch (conv) {
      case 'd':
      case 'i':
        if (isLong)
          std::snprintf(buf, sizeof buf, (spec + "ld").c_str(),
                        static_cast<long>(static_cast<int32_t>(arg())));
        else
          std::snprintf(buf, sizeof buf, (spec + "d").c_str(), static_cast<int>(asInt16(arg())));
        out += buf;
        break;
      case 'u':
      case 'x':
      case 'X':
        if (isLong)
          std::snprintf(buf, sizeof buf, (spec + "l" + conv).c_str(),
                        static_cast<unsigned long>(arg()));
        else
          std::snprintf(buf, sizeof buf, (spec + conv).c_str(),
                        static_cast<unsigned>(arg() & 0xFFFF));
        out += buf;
        break;
      case 'c':
        std::snprintf(buf, sizeof buf, (spec + "c").c_str(), static_cast<int>(arg() & 0xFF));
        out += buf;
        break;
      case 's': {
        std::string s = readString(arg(), 4096);
        std::snprintf(buf, sizeof buf, (spec + "s").c_str(), s.c_str());
        out += buf;
        break;
      }
      case 'f':
      case 'e':
      case 'g':
        std::snprintf(buf, sizeof buf, (spec + conv).c_str(), static_cast<double>(asFloat(arg())));
        out += buf;
        break;
      case '%':
        out.push_back('%');
        break;
      default:
        out += spec;
        out.push_back(conv);
        break;
    }
  }
  return out;
}

// LIB: the call sequence runs first (in steps when it is longer than
// kMaxStepTstates); the routine's effect happens at the end of it.
void Vm::State::libCall(Lib id, int argc, uint32_t instructionPc) {
  lib.id = id;
  lib.pc = instructionPc;
  lib.argc = argc;
  for (int k = argc - 1; k >= 0; --k) lib.args[k] = eval.pop();
  lib.index = 0;
  lib.remaining = 0;
  lib.result = 0;
  uint32_t callCost = costs().libCall[static_cast<int>(id)];
  // abs: JP P is taken (the negation skipped) when the argument is not
  // negative (builtins.def); every other routine costs the same either way.
  if (id == Lib::ABS && asInt16(lib.args[0]) >= 0)
    callCost = static_cast<uint32_t>(static_cast<int32_t>(callCost) +
                                     costs().libTakenDelta[static_cast<int>(id)]);
  // An atomic call (the serial library's DI ... restore idiom) runs its
  // whole sequence with no boundary inside; its effect happens at the next
  // boundary, before any interrupt can be accepted there.
  const uint32_t first =
      kLibAtomic[static_cast<int>(id)] ? callCost : std::min(kMaxStepTstates, callCost);
  now += first;
  if (profiling) profile[instructionPc] += first;
  lib.setup = callCost - first;
  lib.active = true;
  lib.awaitingBegin = lib.setup == 0;
}

void Vm::State::libBegin() {
  lib.active = false;
  lib.awaitingBegin = false;
  const Lib id = lib.id;
  const uint32_t instructionPc = lib.pc;
  const uint32_t* a = lib.args;
  switch (id) {
    case Lib::AD_RD8:
      // Sampled at the start of the conversion, which then takes its time.
      lib.result = w(host().adSample(now, static_cast<int>(asInt16(a[0]))));
      lib.remaining = costs().adConversion;
      lib.active = lib.remaining > 0;
      if (!lib.active) eval.push(lib.result);
      return;
    case Lib::OUTPORT:
      host().out(now, static_cast<uint16_t>(a[0]), static_cast<uint8_t>(a[1]));
      return;
    case Lib::INPORT:
      eval.push(host().in(now, static_cast<uint16_t>(a[0])));
      return;
    case Lib::SER_INIT_Z1:
      // The routine restores the caller's interrupt state (JP PO; EI): IFF1
      // is as it was before the call.
      host().serialInit(now, asInt16(a[0]), asInt16(a[1]));
      return;
    case Lib::SER_SEND_Z1: {
      // The library reads *cc now and buf[0] .. buf[*cc - 1] as it sends:
      // a pointer into the null page or past memory faults the robot here,
      // as the program's own access through it would.
      if (!checkAccess(a[1], 1, instructionPc)) return;
      const uint8_t count = rd8(a[1]);
      if (count > 0 && !checkAccess(a[0], count, instructionPc)) return;
      host().serialSend(now, static_cast<uint16_t>(a[0]), static_cast<uint16_t>(a[1]));
      return;
    }
    case Lib::HV_ENB:
      host().hvEnable(now);
      return;
    case Lib::ABS: {
      int16_t v = asInt16(a[0]);
      eval.push(w(v < 0 ? -v : v));
      return;
    }
    case Lib::FABS:
      eval.push(a[0] & 0x7FFFFFFFu);
      return;
    case Lib::SQRT:
    case Lib::SIN:
    case Lib::COS:
    case Lib::TAN:
    case Lib::ATAN:
    case Lib::ASIN:
    case Lib::ACOS:
    case Lib::EXP:
    case Lib::LOG:
    case Lib::FLOOR:
    case Lib::CEIL:
    case Lib::ATAN2:
    case Lib::POW:
    case Lib::FMOD:
      eval.push(std::bit_cast<uint32_t>(
          mathLib(id, std::bit_cast<float>(a[0]), std::bit_cast<float>(a[1]))));
      return;
    case Lib::DELAYMS:
    case Lib::DELAYSEC:
    case Lib::DELAYTICKS: {
      // DelayTicks' interval is an unsigned int; the others' a long.
      const uint32_t timer = id == Lib::DELAYMS    ? image().timer.ms
                             : id == Lib::DELAYSEC ? image().timer.sec
                                                   : image().timer.tick;
      const auto interval = static_cast<int32_t>(id == Lib::DELAYTICKS ? a[1] & 0xFFFF : a[1]);
      eval.push(delayDone(a[0] & 0xFFFF, interval, timer, instructionPc) ? 1u : 0u);
      return;
    }
    case Lib::COBEGIN:
    case Lib::CORESET:
    case Lib::COPAUSE:
    case Lib::CORESUME:
    case Lib::ISCODONE:
    case Lib::ISCORUNNING: {
      const uint32_t cd = a[0] & 0xFFFF;
      if (!checkAccess(cd, kCoDataSize, instructionPc)) return;
      const uint8_t state = rd8(cd + kCoState);
      switch (id) {
        case Lib::COBEGIN:
        case Lib::CORESET:
          costateEnd(cd, false);
          wr8(cd + kCoFirstTime, 0);
          wr8(cd + kCoState, id == Lib::COBEGIN ? kCoInit : kCoStopped | kCoInit);
          return;
        case Lib::COPAUSE:
          wr8(cd + kCoState, state | kCoStopped);
          return;
        case Lib::CORESUME:
          wr8(cd + kCoState, state & ~kCoStopped);
          return;
        case Lib::ISCODONE:
          eval.push((state & (kCoStopped | kCoInit)) == (kCoStopped | kCoInit) ? 1u : 0u);
          return;
        default:
          eval.push((state & kCoStopped) ? 0u : 1u);
          return;
      }
    }
    case Lib::STRCPY:
    case Lib::MEMSET:
    case Lib::MEMCPY:
      lib.result = a[0] & 0xFFFF;
      lib.active = true;
      return;
    case Lib::STRLEN:
    case Lib::STRCMP:
    case Lib::STRNCMP:
    case Lib::MEMCMP:
    case Lib::STRCHR:
    case Lib::STRRCHR:
    case Lib::ATOI:
      lib.active = true;
      return;
    case Lib::STRCAT:
    case Lib::STRNCPY:
      lib.result = a[0] & 0xFFFF;
      lib.mark = kNoMark;
      lib.active = true;
      return;
    case Lib::SPRINTF:
      lib.text = formatPrintf(instructionPc, 1);
      if (fault) return;
      lib.result = w(static_cast<int32_t>(lib.text.size()));
      lib.active = true;
      return;
    case Lib::PRINTF:
      lib.text = formatPrintf(instructionPc, 0);
      if (fault) return;
      lib.result = w(static_cast<int32_t>(lib.text.size()));
      // Per character: the routine's own loop (builtins.def's step sequence)
      // and the debug port's time for it (knob printf_char_tstates); each
      // line goes to the console when its newline has gone (printfSent).
      lib.remaining = static_cast<uint32_t>(lib.text.size()) * printfCharTstates();
      lib.active = true;
      return;
    case Lib::Count_:
      break;
  }
}

void Vm::State::libFinish(bool pushResult) {
  lib.active = false;
  if (pushResult) eval.push(lib.result);
}

// printf sends its characters one after the other over the debug port,
// each taking its loop's pass and the port's time (libBegin): character i
// (from 0) has gone once (i + 1) x that has passed since the call
// sequence. lib.index counts those given to the console, which stamps a
// line with the tick its newline went.
uint32_t Vm::State::printfCharTstates() const {
  return costs().libStep[static_cast<int>(Lib::PRINTF)] + costs().printfChar;
}

// T-states until the next newline not yet sent has gone (a step ends
// there, so that its line is stamped with that tick), or UINT32_MAX.
uint32_t Vm::State::printfToLineEnd() const {
  const size_t newline = lib.text.find('\n', lib.index);
  const uint32_t perChar = printfCharTstates();
  if (newline == std::string::npos || perChar == 0) return UINT32_MAX;
  const uint32_t elapsed = static_cast<uint32_t>(lib.text.size()) * perChar - lib.remaining;
  return static_cast<uint32_t>(newline + 1) * perChar - elapsed;
}

// Gives the console the characters sent by now.
void Vm::State::printfSent() {
  const uint32_t perChar = printfCharTstates();
  const auto size = static_cast<uint32_t>(lib.text.size());
  const uint32_t sent =
      perChar == 0 || lib.remaining == 0 ? size : (size * perChar - lib.remaining) / perChar;
  if (sent <= lib.index) return;
  emitConsole(std::string_view(lib.text).substr(lib.index, sent - lib.index));
  lib.index = sent;
}

// One step of a long library call: at most kMaxStepTstates T-states of its
// call sequence or of a time it waits (A/D, printf), or one unit of its
// inner loop (a byte copied, compared, set): the Z180's loop is
// interruptible after every byte (LDIR after each, a JR NZ loop between
// any two of its instructions), so a handler sees a copy or fill as far as
// it has gone, not some bytes at a time.
void Vm::State::libStep() {
  const int id = static_cast<int>(lib.id);
  const uint32_t unit = std::max<uint32_t>(1, costs().libStepLooping[id]);
  constexpr uint32_t perStep = 1;
  const uint32_t* a = lib.args;
  ++stats.instructions;
  if (lib.setup > 0) {
    const uint32_t step = std::min(kMaxStepTstates, lib.setup);
    now += step;
    if (profiling) profile[lib.pc] += step;
    lib.setup -= step;
    lib.awaitingBegin = lib.setup == 0;
    return;
  }
  switch (lib.id) {
    case Lib::AD_RD8:
    case Lib::PRINTF: {
      uint32_t step = std::min(kMaxStepTstates, lib.remaining);
      if (lib.id == Lib::PRINTF) step = std::min(step, printfToLineEnd());
      now += step;
      if (profiling) profile[lib.pc] += step;
      lib.remaining -= step;
      if (lib.id == Lib::PRINTF) printfSent();
      if (lib.remaining == 0) {
        lib.text.clear();
        libFinish(true);
      }
      return;
    }
    default:
      break;
  }
  uint32_t done = 0;
  bool finished = false;
  while (done < perStep && !finished) {
    const uint32_t i = lib.index;
    switch (lib.id) {
      case Lib::STRCPY: {
        if (!checkAccess(a[1] + i, 1, lib.pc) || !checkAccess(a[0] + i, 1, lib.pc)) return;
        const uint8_t c = rd8(a[1] + i);
        wr8(a[0] + i, c);
        finished = c == 0;
        break;
      }
      case Lib::STRLEN: {
        if (!checkAccess(a[0] + i, 1, lib.pc)) return;
        if (rd8(a[0] + i) == 0) {
          lib.result = w(static_cast<int32_t>(i));
          finished = true;
        }
        break;
      }
      case Lib::STRCAT: {
        // First the end of dst (mark: where it is), then src copied there.
        if (lib.mark == kNoMark) {
          if (!checkAccess(a[0] + i, 1, lib.pc)) return;
          if (rd8(a[0] + i) == 0) lib.mark = i;
          break;
        }
        const uint32_t k = i - lib.mark - 1;
        if (!checkAccess(a[1] + k, 1, lib.pc) || !checkAccess(a[0] + lib.mark + k, 1, lib.pc))
          return;
        const uint8_t c = rd8(a[1] + k);
        wr8(a[0] + lib.mark + k, c);
        finished = c == 0;
        break;
      }
      case Lib::STRNCPY: {
        // mark: where src ended (NUL from there on).
        const uint32_t n = a[2] & 0xFFFF;
        if (i >= n) {
          finished = true;
          continue;
        }
        uint8_t c = 0;
        if (lib.mark == kNoMark) {
          if (!checkAccess(a[1] + i, 1, lib.pc)) return;
          c = rd8(a[1] + i);
          if (c == 0) lib.mark = i;
        }
        if (!checkAccess(a[0] + i, 1, lib.pc)) return;
        wr8(a[0] + i, c);
        finished = i + 1 >= n;
        break;
      }
      case Lib::STRCMP:
      case Lib::STRNCMP:
      case Lib::MEMCMP: {
        // strcmp is strncmp with no bound; memcmp goes on past a NUL.
        const uint32_t n = lib.id == Lib::STRCMP ? UINT32_MAX : a[2] & 0xFFFF;
        if (i >= n) {
          lib.result = 0;
          finished = true;
          continue;
        }
        if (!checkAccess(a[0] + i, 1, lib.pc) || !checkAccess(a[1] + i, 1, lib.pc)) return;
        const int x = rd8(a[0] + i), y = rd8(a[1] + i);
        if (x != y || (x == 0 && lib.id != Lib::MEMCMP)) {
          lib.result = w(x - y);
          finished = true;
        } else if (i + 1 >= n) {
          lib.result = 0;
          finished = true;
        }
        break;
      }
      case Lib::STRCHR:
      case Lib::STRRCHR: {
        // result (0 from the call: a null pointer) is the latest c seen;
        // strchr stops at the first, strrchr reads on to the NUL.
        if (!checkAccess(a[0] + i, 1, lib.pc)) return;
        const uint8_t c = rd8(a[0] + i);
        const bool match = c == static_cast<uint8_t>(a[1]);
        if (match) lib.result = (a[0] + i) & 0xFFFF;
        finished = c == 0 || (match && lib.id == Lib::STRCHR);
        break;
      }
      case Lib::ATOI: {
        // mark: 0 in the leading white space, 1 after a '-', 2 after '+'
        // or a first digit; result: the value so far, 16-bit.
        if (!checkAccess(a[0] + i, 1, lib.pc)) return;
        const uint8_t c = rd8(a[0] + i);
        if (lib.index == 0) lib.mark = 0;
        if (lib.mark == 0 && (c == ' ' || (c >= '\t' && c <= '\r'))) break;
        if (lib.mark == 0 && (c == '-' || c == '+')) {
          lib.mark = c == '-' ? 1 : 2;
          break;
        }
        if (c >= '0' && c <= '9') {
          if (lib.mark == 0) lib.mark = 2;
          const int32_t digit = c - '0';
          const int32_t sofar = asInt16(lib.result);
          lib.result = w(sofar * 10 + (lib.mark == 1 ? -digit : digit));
          break;
        }
        finished = true;
        break;
      }
      case Lib::SPRINTF: {
        // The formatted text, then its NUL, one character a step.
        const uint32_t dst = a[0] + i;
        if (!checkAccess(dst, 1, lib.pc)) return;
        finished = i >= lib.text.size();
        wr8(dst, finished ? 0 : static_cast<uint8_t>(lib.text[i]));
        if (finished) lib.text.clear();
        break;
      }
      case Lib::MEMSET:
      case Lib::MEMCPY: {
        const uint32_t n = a[2] & 0xFFFF;
        if (i >= n) {
          finished = true;
          continue;
        }
        if (!checkAccess(a[0] + i, 1, lib.pc)) return;
        if (lib.id == Lib::MEMSET) {
          wr8(a[0] + i, a[1]);
        } else {
          if (!checkAccess(a[1] + i, 1, lib.pc)) return;
          wr8(a[0] + i, rd8(a[1] + i));
        }
        finished = i + 1 >= n;
        break;
      }
      default:
        finished = true;
        break;
    }
    ++lib.index;
    ++done;
  }
  // Every unit loops back (its branch taken) but the routine's last.
  const uint32_t last = costs().libStep[id];
  const uint32_t cost = done * unit - (finished && done > 0 ? unit - last : 0);
  now += cost;
  if (profiling) profile[lib.pc] += cost;
  if (finished) libFinish(true);
}

}  // namespace simbot::vm
