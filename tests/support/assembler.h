// A minimal bytecode assembler for VM tests that must not depend on the
// compiler: emit opcodes with operands, bind labels, patch jumps.
#pragma once
#include <cstring>
#include <map>
#include <string>

#include "vm/bytecode.h"
#include "vm/image.h"

namespace simbot::testkit {

class Assembler {
 public:
  vm::Image image;
  int line = 1;

  uint32_t here() const { return static_cast<uint32_t>(image.code.size()); }
  Assembler& op(vm::Op o) {
    byte(static_cast<uint8_t>(o));
    return *this;
  }
  Assembler& op(vm::Op o, uint32_t operand) {
    op(o);
    const int n = vm::operandBytes(vm::info(o).shape);
    for (int i = 0; i < n; ++i) byte(static_cast<uint8_t>(operand >> (8 * i)));
    return *this;
  }
  Assembler& lib(vm::Lib l, int argc) {
    op(vm::Op::LIB);
    byte(static_cast<uint8_t>(l));
    byte(static_cast<uint8_t>(argc));
    return *this;
  }
  // Jump to a label bound now or later.
  Assembler& jump(vm::Op o, const std::string& label) {
    op(o);
    fixups_.emplace(here(), label);
    byte(0);
    byte(0);
    return *this;
  }
  Assembler& bind(const std::string& label) {
    labels_[label] = here();
    return *this;
  }
  uint32_t label(const std::string& name) const { return labels_.at(name); }
  // Reserve `size` bytes of data; returns its address.
  uint16_t data(uint32_t size) {
    const auto at = static_cast<uint16_t>(vm::kDataBase + image.data.size());
    image.data.resize(image.data.size() + size, 0);
    return at;
  }
  uint16_t string(const std::string& s) {
    const uint16_t at = data(static_cast<uint32_t>(s.size() + 1));
    std::memcpy(&image.data[at - vm::kDataBase], s.c_str(), s.size() + 1);
    return at;
  }
  vm::Image finish() {
    for (const auto& [at, name] : fixups_) {
      const int32_t rel = static_cast<int32_t>(labels_.at(name)) - static_cast<int32_t>(at + 2);
      image.code[at] = static_cast<uint8_t>(rel);
      image.code[at + 1] = static_cast<uint8_t>(rel >> 8);
    }
    return image;
  }

 private:
  void byte(uint8_t b) {
    image.code.push_back(b);
    image.lines.push_back(line);
  }
  std::map<std::string, uint32_t> labels_;
  std::multimap<uint32_t, std::string> fixups_;
};

// A handler at label "handler", on PIO port A's vector, that counts into
// `counter` and returns.
inline void countingHandler(Assembler& a, uint16_t counter) {
  a.bind("handler").op(vm::Op::INCGW, counter).op(vm::Op::RETI);
  a.image.vectors.push_back({vm::kVecPIOA, static_cast<uint16_t>(a.label("handler")), "handler"});
}

}  // namespace simbot::testkit
