#include "vm/image.h"

#include <algorithm>

#include "vm/bytecode.h"

namespace simbot::vm {

const Symbol* Image::functionAt(uint32_t codeAddress) const {
  const Symbol* best = nullptr;
  for (const auto& s : symbols) {
    if (s.kind != Symbol::Kind::Function && s.kind != Symbol::Kind::Handler) continue;
    if (codeAddress >= s.address && codeAddress < s.address + s.size) return &s;
    if (s.address <= codeAddress && (!best || s.address > best->address)) best = &s;
  }
  return best;
}

const Image::Entry* Image::entryAt(uint32_t codeAddress) const {
  auto it = std::lower_bound(entries.begin(), entries.end(), codeAddress,
                             [](const Entry& e, uint32_t a) { return e.address < a; });
  return it != entries.end() && it->address == codeAddress ? &*it : nullptr;
}

std::vector<int32_t> Image::returnFrames() const {
  const auto size = static_cast<uint32_t>(code.size());
  std::vector<uint8_t> starts(size, 0);
  auto mark = [&](uint32_t a) {
    if (a < size) starts[a] = 1;
  };
  for (const auto& s : symbols)
    if (s.kind == Symbol::Kind::Function || s.kind == Symbol::Kind::Handler) mark(s.address);
  for (const auto& v : vectors) mark(v.handler);
  std::vector<int32_t> frames(size, -1);
  // Two walks: CALL targets first (a CALL may target a function later in
  // the code), then the frames.
  for (uint32_t at = 0; at < size;) {
    if (code[at] >= kOpCount) {
      ++at;
      continue;
    }
    const auto op = static_cast<Op>(code[at]);
    if (op == Op::CALL && at + 3 <= size)
      mark(static_cast<uint32_t>(code[at + 1] | (code[at + 2] << 8)));
    at += static_cast<uint32_t>(instructionSize(op));
  }
  int32_t frame = -1;
  for (uint32_t at = 0; at < size;) {
    if (starts[at])
      frame = code[at] == static_cast<uint8_t>(Op::ENTER) && at + 3 <= size
                  ? static_cast<int32_t>(code[at + 1] | (code[at + 2] << 8))
                  : -1;
    if (code[at] >= kOpCount) {
      ++at;
      continue;
    }
    const auto op = static_cast<Op>(code[at]);
    if (op == Op::RET) frames[at] = frame;
    at += static_cast<uint32_t>(instructionSize(op));
  }
  return frames;
}

std::optional<uint32_t> Image::loopHead(int line) const {
  std::optional<uint32_t> head;
  for (uint32_t at = 0; at < code.size();) {
    if (code[at] >= kOpCount) return head;  // not code: the walk cannot go on
    const auto op = static_cast<Op>(code[at]);
    const auto size = static_cast<uint32_t>(instructionSize(op));
    if (at + size > code.size()) break;
    if (info(op).shape == Shape::REL16 && lineAt(at) == line) {
      const auto rel = static_cast<int16_t>(code[at + 1] | (code[at + 2] << 8));
      const int64_t target = int64_t{at} + size + rel;
      if (target >= 0 && target <= at && lineAt(static_cast<uint32_t>(target)) == line &&
          (!head || target < *head))
        head = static_cast<uint32_t>(target);
    }
    at += size;
  }
  return head;
}

}  // namespace simbot::vm
