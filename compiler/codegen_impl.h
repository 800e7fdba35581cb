// compiler/codegen_impl.h -- internal: the code generator's class and what
// its parts share. codegen.cpp emits, lays out data and generates functions
// and statements; gen_expr.cpp generates expressions. Nothing outside
// compiler/ includes this header.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>

#include "compiler/ast.h"
#include "vm/bytecode.h"
#include "vm/image.h"

namespace simbot::compiler::detail {

using vm::Op;

inline constexpr int kDataLimit = 0xF000;  // the rest is left to the stack

// How the image's readers (--watch) must take a data symbol's memory.
inline vm::Symbol::Value symbolValue(const Type* t) {
  using V = vm::Symbol::Value;
  switch (t->kind) {
    case TypeKind::Char:
      return V::Char;
    case TypeKind::SChar:
      return V::SChar;
    case TypeKind::Int:
      return V::Int;
    case TypeKind::UInt:
      return V::UInt;
    case TypeKind::Long:
      return V::Long;
    case TypeKind::ULong:
      return V::ULong;
    case TypeKind::Float:
      return V::Float;
    case TypeKind::Ptr:
      return V::Pointer;
    case TypeKind::Func:
      return V::Code;
    case TypeKind::Void:
    case TypeKind::Array:
    case TypeKind::Struct:
    case TypeKind::Union:
      break;
  }
  return V::Aggregate;
}

// Where an lvalue lives: an absolute address, a frame offset, or an address
// already pushed on the eval stack.
struct Loc {
  enum Kind { Global, Frame, Stack } kind = Stack;
  int addr = 0;
};

// How a value is represented for conversions.
// A signed char's slot holds its value sign-extended to 16 bits (SXB after
// every load), a char's zero-extended: both promote to int for free.
enum class Rep { Byte, ByteS, WordS, WordU, LongS, LongU, Float, Other };

inline Rep repOf(const Type* t) {
  switch (t->kind) {
    case TypeKind::Char:
      return Rep::Byte;
    case TypeKind::SChar:
      return Rep::ByteS;
    case TypeKind::Int:
      return Rep::WordS;
    case TypeKind::UInt:
    case TypeKind::Ptr:
    case TypeKind::Array:
      return Rep::WordU;
    case TypeKind::Long:
      return Rep::LongS;
    case TypeKind::ULong:
      return Rep::LongU;
    case TypeKind::Float:
      return Rep::Float;
    default:
      return Rep::Other;
  }
}

// Which of a load or store family's byte, word and long forms fits `r`.
inline int widthIndex(Rep r) {
  if (r == Rep::Byte || r == Rep::ByteS) return 0;
  return r == Rep::WordS || r == Rep::WordU ? 1 : 2;
}

inline bool isAggregate(const Type* t) { return t->kind == TypeKind::Array || isStructLike(t); }

// The image's type table, one entry per distinct type (debug_info.cpp).
class DebugTypes {
 public:
  int32_t id(const Type* t);  // -1 for none
  std::vector<vm::TypeInfo> take() { return std::move(types_); }

 private:
  std::unordered_map<const Type*, int32_t> ids_;
  std::vector<vm::TypeInfo> types_;
};

class CodeGen {
 public:
  explicit CodeGen(Program& prog) : prog_(prog) {}
  vm::Image run();

 private:
  // ---- emission ----
  void emit(Op op, int line);
  void emitU16(Op op, int value, int line);
  void emitI32(Op op, int32_t value, int line);
  void emitF32(Op op, float value, int line);
  void emitByte(uint8_t b, int line);
  int newLabel();
  void bind(int label);
  void jump(Op op, int label, int line);
  void coJump(Op op, int coData, int label, int line);  // CO shape
  void rel16(int label, int line);  // a REL16 operand to `label`, fixed up later
  void pushConst(const Type* t, int64_t v, int line);

  // ---- data ----
  int allocData(int size, Pos pos, const std::string& what);
  int stringAddress(const std::string& s, Pos pos);
  void writeData(int addr, uint64_t value, int size);
  void writeInit(const Init* init, int addr);
  // A variable with an initialiser is given all its bytes at load.
  void markInitialised(int addr, int size);
  bool staticPtr(Node* e, Loc& out);
  bool staticLoc(Node* e, Loc& out);

  // ---- functions and statements ----
  void function(Function* f);
  void stmt(Node* n);
  void declInit(Node* n);
  void costate(Node* n);
  bool isDelayLoop(const Node* n) const;
  void waitfor(Node* n);
  void costateYield(Node* costate, int resumeLabel, int line);
  void costateClose(Node* costate, int line);
  void bindResumePoint(int label);
  void autoInitStores(const Init* init, int off, int line);

  // ---- expressions ----
  Loc addr(Node* n);
  Loc accessible(Loc l, const Type* t, int line);
  void pushAddress(const Loc& l, int line);
  void load(const Loc& l, const Type* t, int line);
  void store(const Loc& l, const Type* t, bool keep, int line);
  void value(Node* n);
  void effect(Node* n);
  void cond(Node* n, int label, bool jumpIf);
  void convert(const Type* from, const Type* to, int line);
  void storeValue(Node* rhs, const Type* target, bool keep);
  void arithOp(NodeKind k, const Type* t, int line);
  void compareOp(NodeKind k, const Type* t, int line);
  void assign(Node* n, bool keep);
  void opAssign(Node* n, bool keep);
  void incDec(Node* n, bool keep);
  bool superInstruction(Node* n);
  void call(Node* n);
  void libCall(Node* n);

  Program& prog_;
  vm::Image img_;
  int dataTop_ = vm::kDataBase;
  std::unordered_map<std::string, int> strings_;

  struct Label {
    int addr = -1;
    std::vector<int> fixups;  // offsets of REL16 operands
  };
  std::vector<Label> labels_;
  std::vector<std::pair<int, Function*>> callFixups_;
  std::vector<std::pair<int, Function*>> dataFixups_;  // function addresses in initialisers
  Function* fn_ = nullptr;
  Pos curPos_;
  std::vector<int> breaks_;
  std::vector<int> continues_;
  std::unordered_map<std::string, int> userLabels_;
  int epilogue_ = -1;
};

}  // namespace simbot::compiler::detail
