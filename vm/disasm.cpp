// Disassembler: one line per instruction (address, T-states by path, name,
// operands), a label at each function and the source line above the code it
// produced.
// One small helper per operand shape, as in craftinginterpreters' debug.c.
#include <fmt/format.h>

#include <bit>
#include <map>

#include "vm/cost_sums.h"
#include "vm/vm.h"

namespace simbot::vm {

namespace {

uint32_t readU16(const Image& img, uint32_t at) { return img.code[at] | (img.code[at + 1] << 8); }
uint32_t readU32(const Image& img, uint32_t at) {
  return readU16(img, at) | (readU16(img, at + 2) << 16);
}

std::string noOperand(const Image&, uint32_t) { return ""; }
std::string u8Operand(const Image& img, uint32_t at) { return fmt::format("{}", img.code[at]); }
std::string u16Operand(const Image& img, uint32_t at) {
  return fmt::format("0x{:04x}", readU16(img, at));
}
std::string rel16Operand(const Image& img, uint32_t at) {
  const int16_t rel = static_cast<int16_t>(readU16(img, at));
  return fmt::format("-> {:04x}", at + 2 + rel);
}
std::string i32Operand(const Image& img, uint32_t at) {
  return fmt::format("{}", static_cast<int32_t>(readU32(img, at)));
}
std::string f32Operand(const Image& img, uint32_t at) {
  return fmt::format("{}", std::bit_cast<float>(readU32(img, at)));
}
std::string libOperand(const Image& img, uint32_t at) {
  const int id = img.code[at];
  const std::string_view name = id < kLibCount ? kLibInfo[id].name : "?";
  return fmt::format("{}, {} args", name, img.code[at + 1]);
}

std::string coOperand(const Image& img, uint32_t at) {
  return fmt::format("0x{:04x}, {}", readU16(img, at), rel16Operand(img, at + 2));
}

std::string operandText(Shape shape, const Image& img, uint32_t at) {
  switch (shape) {
    case Shape::NONE:
      return noOperand(img, at);
    case Shape::U8:
      return u8Operand(img, at);
    case Shape::U16:
      return u16Operand(img, at);
    case Shape::REL16:
      return rel16Operand(img, at);
    case Shape::I32:
      return i32Operand(img, at);
    case Shape::F32:
      return f32Operand(img, at);
    case Shape::LIB:
      return libOperand(img, at);
    case Shape::CO:
      return coOperand(img, at);
  }
  return "";
}

// Names a data address or a code address where the symbol table knows it.
std::string annotate(const Image& img, Op op, uint32_t at) {
  const Shape shape = info(op).shape;
  if (shape != Shape::U16 && shape != Shape::CO) return "";
  const uint32_t value = readU16(img, at);
  const bool codeAddress = op == Op::CALL;
  const bool dataAddress = op == Op::LDGB || op == Op::LDGW || op == Op::LDGL || op == Op::STGB ||
                           op == Op::STGW || op == Op::STGL || op == Op::INCGW || op == Op::DECGW ||
                           op == Op::INCGL || shape == Shape::CO || op == Op::COEND ||
                           op == Op::CODONE;
  for (const auto& s : img.symbols) {
    const bool isCode = s.kind == Symbol::Kind::Function || s.kind == Symbol::Kind::Handler;
    if (codeAddress && isCode && s.address == value) return s.name;
    if (dataAddress && !isCode && s.kind != Symbol::Kind::Auto && s.kind != Symbol::Kind::Param &&
        value >= s.address && value < s.address + std::max<uint32_t>(1, s.size))
      return value == s.address ? s.name : fmt::format("{}+{}", s.name, value - s.address);
  }
  return "";
}

// An instruction's T-states under the calibrated knobs, by path:
//   "23"           no conditional branch;
//   "26/23"        one branch: taken / not taken (a library call whose
//                  path its argument picks, abs, likewise);
//   "58/59/59/61"  two branches (the signed comparisons): both taken /
//                  first only / second only / neither;
//   "31/30+18n"    a loop of n passes (the 16-bit shifts): count 0, its
//                  JR Z taken over the loop / n >= 1 passes;
//   "41+26n"       a library routine with an inner loop, n its units
//                  (bytes, characters; ad_rd8: "+N" its conversion);
//   "30/84/85"     COSTATE: stopped (paused or done) / entered fresh /
//                  resumed.
std::string costText(const CostTable& costs, Op op, const Image& img, uint32_t operandAt) {
  const int i = static_cast<int>(op);
  const auto path = [&](unsigned p) {
    return static_cast<int64_t>(costs.op[i]) + costs.branchDelta[i][p];
  };
  if (op == Op::LIB) {
    const int id = img.code[operandAt];
    if (id >= kLibCount) return fmt::format("{}", costs.op[i]);
    const int64_t call = int64_t{costs.op[i]} + costs.libCall[id];
    std::string text = libPathFromArguments(static_cast<Lib>(id))
                           ? fmt::format("{}/{}", call + costs.libTakenDelta[id], call)
                           : fmt::format("{}", call);
    // What the VM adds after the call sequence: the A/D conversion, or the
    // inner loop once per unit (a printf character also the debug port's).
    if (static_cast<Lib>(id) == Lib::AD_RD8) return text + fmt::format("+{}", costs.adConversion);
    if (kLibInfo[id].unit.empty()) return text;
    if (static_cast<Lib>(id) == Lib::PRINTF)
      return text + fmt::format("+{}n", costs.libStep[id] + costs.printfChar);
    // n units: n - 1 looping back, the last falling through.
    const int64_t lastSaves = int64_t{costs.libStepLooping[id]} - costs.libStep[id];
    if (lastSaves == 0) return text + fmt::format("+{}n", costs.libStep[id]);
    const int64_t callLess = call - lastSaves;
    text = libPathFromArguments(static_cast<Lib>(id))
               ? fmt::format("{}/{}", callLess + costs.libTakenDelta[id], callLess)
               : fmt::format("{}", callLess);
    return text + fmt::format("+{}n", costs.libStepLooping[id]);
  }
  if (op == Op::COSTATE) {
    // Its JP Z leaves the sequence when taken: a STOPPED costatement costs
    // kCostateStoppedSeq; the others go on to the JR Z, taken when fresh.
    return fmt::format("{}/{}/{}", int64_t{costs.op[i]} + costs.costateStoppedDelta, path(2),
                       path(0));
  }
  const SeqCost& seq = kOpSeqCost[i];
  if (seq.loops > 0) {
    const int64_t pass = costs.loopPass[i];
    return fmt::format("{}/{}+{}n", path(1), int64_t{costs.op[i]} - pass, pass);
  }
  if (seq.branches == 1) return fmt::format("{}/{}", path(1), path(0));
  if (seq.branches == 2) return fmt::format("{}/{}/{}/{}", path(3), path(1), path(2), path(0));
  return fmt::format("{}", costs.op[i]);
}

// One instruction's name, operands (with the symbol they name) and
// T-states, as the listing and the debugger's stepi show it.
struct Parts {
  std::string name, operands, cost;
};
Parts instructionParts(const Image& img, const CostTable& costs,
                       const std::vector<int32_t>& returnFrames, uint32_t at) {
  const Op op = static_cast<Op>(img.code[at]);
  std::string operands = operandText(info(op).shape, img, at + 1);
  const std::string note = annotate(img, op, at + 1);
  if (!note.empty()) operands += fmt::format("  ({})", note);
  std::string cost = costText(costs, op, img, at + 1);
  if (op == Op::RET && returnFrames[at] >= 0)
    cost = fmt::format("{}", costs.op[static_cast<int>(op)] + costs.autoFrameRet);
  if (op == Op::COPY) {  // LDIR repeats for every byte but the last
    const uint32_t n = img.code[at + 1] | (img.code[at + 2] << 8);
    cost =
        fmt::format("{}", costs.op[static_cast<int>(op)] + (n > 1 ? n - 1 : 0) * costs.ldirRepeat);
  }
  return {std::string(info(op).name), operands, cost};
}

}  // namespace

std::string disassembleAt(const Image& img, uint32_t at) {
  return disassembleAt(img, at, makeCostTable(calibratedKnobs()));
}

std::string disassembleAt(const Image& img, uint32_t at, const CostTable& costs) {
  if (at >= img.code.size()) return fmt::format("{:04x}  (outside the code)", at);
  const uint8_t byte = img.code[at];
  if (byte >= kOpCount) return fmt::format("{:04x}  .byte {}", at, byte);
  const Op op = static_cast<Op>(byte);
  if (at + static_cast<uint32_t>(instructionSize(op)) > img.code.size())
    return fmt::format("{:04x}  {} (truncated)", at, info(op).name);
  const auto [name, operands, cost] = instructionParts(img, costs, img.returnFrames(), at);
  return fmt::format("{:04x}  {:<8} {}  [{} T-states]", at, name, operands, cost);
}

std::string disassemble(const Image& img) {
  const CostTable costs = makeCostTable(calibratedKnobs());
  std::map<uint32_t, std::string> labels;
  for (const auto& s : img.symbols)
    if (s.kind == Symbol::Kind::Function || s.kind == Symbol::Kind::Handler)
      labels[s.address] = s.kind == Symbol::Kind::Handler ? s.name + " (interrupt)" : s.name;

  std::string out = fmt::format("; {}: {} code bytes, {} data bytes at 0x{:04x}\n", img.sourceName,
                                img.code.size(), img.data.size(), kDataBase);
  for (const auto& v : img.vectors)
    out += fmt::format("; vector 0x{:02x} -> {} at {:04x}\n", v.vector, v.handlerName, v.handler);
  out += fmt::format("; {:<4}  {:>11}  {:<8} {}\n", "addr", "T-st", "op", "operands");
  int lastLine = -1;
  uint32_t at = 0;
  // A RET in a function that began with ENTER (a #class auto frame) also
  // pops IX, as the VM charges it: the same table the VM decodes.
  const std::vector<int32_t> returnFrames = img.returnFrames();
  while (at < img.code.size()) {
    if (auto it = labels.find(at); it != labels.end()) out += fmt::format("\n{}:\n", it->second);
    const int line = img.lineAt(at);
    if (line != lastLine && line > 0) {
      const std::string text = line <= static_cast<int>(img.sourceLines.size())
                                   ? img.sourceLines[line - 1]
                                   : std::string();
      out += fmt::format("{:33}; {:>4} | {}\n", "", line, text);
      lastLine = line;
    }
    const uint8_t byte = img.code[at];
    if (byte >= kOpCount) {
      out += fmt::format("  {:04x}        .byte {}\n", at, byte);
      ++at;
      continue;
    }
    const Op op = static_cast<Op>(byte);
    const int size = instructionSize(op);
    if (at + size > img.code.size()) {
      out += fmt::format("  {:04x}        {} (truncated)\n", at, info(op).name);
      break;
    }
    const auto [name, operands, cost] = instructionParts(img, costs, returnFrames, at);
    out += fmt::format("  {:04x}  {:>11}  {:<8} {}\n", at, cost, name, operands);
    at += static_cast<uint32_t>(size);
  }
  return out;
}

}  // namespace simbot::vm
