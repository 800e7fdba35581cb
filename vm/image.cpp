#include "vm/image.h"

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

}  // namespace simbot::vm
