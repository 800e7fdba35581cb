// The bytecode: one definition of every opcode (opcodes.def) turned into the
// enum, names, operand shapes and stack effects used by the compiler, the VM
// and the disassembler.
//
// Encoding (little-endian), drawn once:
//
//   +--------+------------------------------+
//   | opcode | operands (0, 1, 2 or 4 bytes) |
//   +--------+------------------------------+
//     1 byte   NONE   -
//              U8     u8
//              U16    u16  address, size, frame offset or code address
//              REL16  i16  jump target = address of the next instruction + i16
//              I32    i32  constant
//              F32    f32  constant (IEEE single bits)
//              LIB    u8 builtin id, u8 argument count
//              CO     u16 CoData address, then i16 relative target as REL16
//
// The eval stack holds 32-bit slots: a W value uses its low 16 bits, a B
// value is zero-extended, an F value is its IEEE bits. Functions leave one
// slot on return (0 for void); arguments are pushed left to right and the
// callee's prologue pops them into its parameters.
#pragma once
#include <cstdint>
#include <string_view>

namespace simbot::vm {

enum class Op : uint8_t {
#define OP(name, shape, pop, push, seq) name,
#include "opcodes.def"
#undef OP
  Count_
};
inline constexpr int kOpCount = static_cast<int>(Op::Count_);

enum class Shape : uint8_t { NONE, U8, U16, REL16, I32, F32, LIB, CO };

// A library call takes at most this many arguments (printf's format and
// values included): the compiler refuses more, the VM faults on more.
inline constexpr int kMaxLibArgs = 32;

constexpr int operandBytes(Shape s) {
  switch (s) {
    case Shape::NONE:
      return 0;
    case Shape::U8:
      return 1;
    case Shape::U16:
    case Shape::REL16:
    case Shape::LIB:
      return 2;
    case Shape::I32:
    case Shape::F32:
    case Shape::CO:
      return 4;
  }
  return 0;
}

struct OpInfo {
  std::string_view name;
  Shape shape;
  int8_t pop;             // -1: depends on operands
  int8_t push;            // -1: depends on operands
  std::string_view z180;  // the Z180 sequence whose T-states are its cost
};

inline constexpr OpInfo kOpInfo[] = {
#define OP(name, shape, pop, push, seq) {#name, Shape::shape, pop, push, seq},
#include "opcodes.def"
#undef OP
};

constexpr const OpInfo& info(Op op) { return kOpInfo[static_cast<int>(op)]; }
constexpr int instructionSize(Op op) { return 1 + operandBytes(info(op).shape); }

// The slots an instruction takes from the expression stack: opcodes.def's
// count, or where that depends on the operands, CALL none (its callee's
// prologue takes the arguments), CALLI the function's address, LIB its
// arguments (the byte after its routine's id).
constexpr int slotsTaken(Op op, const uint8_t* instruction) {
  if (op == Op::CALL) return 0;
  if (op == Op::CALLI) return 1;
  if (op == Op::LIB) return instruction[2];
  return info(op).pop;
}

// Builtin library routines (builtins.def).
enum class Lib : uint8_t {
#define BUILTIN(id, name, ret, args, call, step, unit) id,
#include "builtins.def"
#undef BUILTIN
  Count_
};
inline constexpr int kLibCount = static_cast<int>(Lib::Count_);
// The LIB operand is the routine's id in its low byte and the argument
// count in its high byte (codegen.cpp libCall, vm.cpp LIB).
static_assert(kLibCount <= 256, "a library id must fit the LIB operand's low byte");
static_assert(kMaxLibArgs >= 1 && kMaxLibArgs <= 255,
              "the argument limit must fit the LIB operand's high byte");

struct LibInfo {
  std::string_view name;
  char result;            // type letter, see builtins.def
  std::string_view args;  // type letters; trailing '.' = variadic
  std::string_view callSeq;
  std::string_view stepSeq;
  std::string_view unit;
};

inline constexpr LibInfo kLibInfo[] = {
#define BUILTIN(id, name, ret, args, call, step, unit) {name, ret, args, call, step, unit},
#include "builtins.def"
#undef BUILTIN
};

constexpr const LibInfo& info(Lib lib) { return kLibInfo[static_cast<int>(lib)]; }

// MATH.LIB's routines (SQRT through FMOD, kept together in builtins.def):
// known to a program only after its #use MATH.LIB, as in Dynamic C, so that
// a program's own pow() or floor() keeps working without it.
constexpr bool inMathLib(int id) {
  return id >= static_cast<int>(Lib::SQRT) && id <= static_cast<int>(Lib::FMOD);
}

// The library routine a program names, by its C name: its id, or -1.
constexpr int libraryIndex(std::string_view name) {
  for (int i = 0; i < kLibCount; ++i)
    if (kLibInfo[i].name == name) return i;
  return -1;
}

}  // namespace simbot::vm
