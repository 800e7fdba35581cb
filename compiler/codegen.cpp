// The code generator: typed syntax tree in, bytecode image out.
//
// A deliberately naive one-pass stack-machine generator, like a 1990s
// non-optimising compiler: every expression leaves its value in one eval-stack
// slot; globals and statics are addressed absolutely, autos FP-relative.
// The few things it does beyond that are the ones the cycle model relies on:
// assignments used as statements store without DUP/POP, "x++" on a 16-bit
// (or, incrementing, 32-bit) static compiles to INCGW/DECGW/INCGL, addresses
// that are known at compile time (buf[3], s.x) use the absolute or frame
// forms, and conditions jump directly (short-circuit && and ||).
//
// Layout: code address 0 holds the start-up stub "CALL main; POP; HALT",
// then the functions in source order. Data starts at vm::kDataBase and is
// packed without alignment: first the globals in declaration order, then the
// string literals their initialisers use, then, function by function as they
// are compiled, their statics, switch temporaries and string literals.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>

#include "compiler/ast.h"
#include "vm/bytecode.h"
#include "vm/image.h"

namespace simbot::compiler {

namespace {

using vm::Op;

constexpr int kDataLimit = 0xF000;  // the rest is left to the stack

// How the image's readers (--watch) must take a data symbol's memory.
vm::Symbol::Value symbolValue(const Type* t) {
  using V = vm::Symbol::Value;
  switch (t->kind) {
    case TypeKind::Char:
      return V::Char;
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
enum class Rep { Byte, WordS, WordU, LongS, LongU, Float, Other };

Rep repOf(const Type* t) {
  switch (t->kind) {
    case TypeKind::Char:
      return Rep::Byte;
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

bool isAggregate(const Type* t) { return t->kind == TypeKind::Array || isStructLike(t); }

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
  Function* fn_ = nullptr;
  Pos curPos_;
  std::vector<int> breaks_;
  std::vector<int> continues_;
  std::unordered_map<std::string, int> userLabels_;
  int epilogue_ = -1;
};

// ===================================================================
// Emission.

void CodeGen::emitByte(uint8_t b, int line) {
  if (img_.code.size() >= 0xFFFF) fail(curPos_, "program is too large (more than 64 KiB of code)");
  img_.code.push_back(b);
  img_.lines.push_back(line);
}

void CodeGen::emit(Op op, int line) { emitByte(static_cast<uint8_t>(op), line); }

void CodeGen::emitU16(Op op, int value, int line) {
  emit(op, line);
  emitByte(static_cast<uint8_t>(value & 0xFF), line);
  emitByte(static_cast<uint8_t>((value >> 8) & 0xFF), line);
}

void CodeGen::emitI32(Op op, int32_t value, int line) {
  emit(op, line);
  uint32_t v = static_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) emitByte(static_cast<uint8_t>(v >> (8 * i)), line);
}

void CodeGen::emitF32(Op op, float value, int line) {
  uint32_t bits;
  std::memcpy(&bits, &value, 4);
  emitI32(op, static_cast<int32_t>(bits), line);
}

int CodeGen::newLabel() {
  labels_.emplace_back();
  return static_cast<int>(labels_.size()) - 1;
}

void CodeGen::bind(int label) { labels_[label].addr = static_cast<int>(img_.code.size()); }

void CodeGen::rel16(int label, int line) {
  labels_[label].fixups.push_back(static_cast<int>(img_.code.size()));
  emitByte(0, line);
  emitByte(0, line);
}

void CodeGen::jump(Op op, int label, int line) {
  emit(op, line);
  rel16(label, line);
}

void CodeGen::coJump(Op op, int coData, int label, int line) {
  emitU16(op, coData, line);
  rel16(label, line);
}

void CodeGen::pushConst(const Type* t, int64_t v, int line) {
  switch (repOf(t)) {
    case Rep::LongS:
    case Rep::LongU:
      emitI32(Op::PUSHL, static_cast<int32_t>(static_cast<uint32_t>(v)), line);
      break;
    case Rep::Float:
      emitF32(Op::PUSHF, static_cast<float>(v), line);
      break;
    default:
      emitU16(Op::PUSHW, static_cast<int>(v & 0xFFFF), line);
      break;
  }
}

// ===================================================================
// Data.

int CodeGen::allocData(int size, Pos pos, const std::string& what) {
  if (dataTop_ + size > kDataLimit)
    fail(pos, "too much data: " + what + " does not fit below address 0xF000");
  int a = dataTop_;
  dataTop_ += size;
  img_.data.resize(static_cast<size_t>(dataTop_ - vm::kDataBase), 0);
  img_.initialised.resize(img_.data.size(), 0);
  return a;
}

// String literals: one NUL-terminated copy of each distinct text.
int CodeGen::stringAddress(const std::string& s, Pos pos) {
  auto it = strings_.find(s);
  if (it != strings_.end()) return it->second;
  int a = allocData(static_cast<int>(s.size()) + 1, pos, "a string literal");
  std::memcpy(img_.data.data() + (a - vm::kDataBase), s.data(), s.size());
  markInitialised(a, static_cast<int>(s.size()) + 1);
  strings_[s] = a;
  return a;
}

void CodeGen::writeData(int addr, uint64_t value, int size) {
  for (int i = 0; i < size; ++i)
    img_.data[static_cast<size_t>(addr - vm::kDataBase + i)] =
        static_cast<uint8_t>(value >> (8 * i));
}

void CodeGen::markInitialised(int addr, int size) {
  std::fill_n(img_.initialised.begin() + (addr - vm::kDataBase), size, uint8_t{1});
}

// The initial bytes of a global or static (applied once, at load).
void CodeGen::writeInit(const Init* init, int a) {
  const Type* t = init->type;
  if (!init->expr) {
    if (t->kind == TypeKind::Array) {
      for (size_t i = 0; i < init->children.size(); ++i)
        writeInit(init->children[i], a + static_cast<int>(i) * t->base->size);
    } else {
      for (size_t i = 0; i < init->children.size(); ++i)
        writeInit(init->children[i], a + t->members[i].offset);
    }
    return;
  }
  Node* e = init->expr;
  if (t->kind == TypeKind::Array) {  // char array from a string literal
    size_t n = std::min(e->str.size() + 1, static_cast<size_t>(t->arrayLen));
    std::memcpy(img_.data.data() + (a - vm::kDataBase), e->str.data(), std::min(n, e->str.size()));
    return;
  }
  curPos_ = e->pos;
  if (e->kind == NodeKind::Num) {
    writeData(a, static_cast<uint64_t>(e->ival), t->size);
    return;
  }
  if (e->kind == NodeKind::FNum) {
    uint32_t bits;
    std::memcpy(&bits, &e->fval, 4);
    writeData(a, bits, 4);
    return;
  }
  Loc l;
  if (t->size == 2 && staticPtr(e, l) && l.kind == Loc::Global) {
    writeData(a, static_cast<uint64_t>(l.addr), 2);
    return;
  }
  fail(e->pos, "initializer element is not constant");
}

// The address a pointer-valued expression has, if known at compile time.
bool CodeGen::staticPtr(Node* e, Loc& out) {
  switch (e->kind) {
    case NodeKind::Var:
      if (e->type->kind != TypeKind::Array) return false;
      return staticLoc(e, out);
    case NodeKind::Str:
      out = Loc{Loc::Global, stringAddress(e->str, e->pos)};
      return true;
    case NodeKind::Addr:
      return staticLoc(e->lhs, out);
    case NodeKind::Num:
      if (e->type->kind != TypeKind::Ptr) return false;
      out = Loc{Loc::Global, static_cast<int>(e->ival & 0xFFFF)};
      return true;
    case NodeKind::Cast:
      if (!isPtrLike(e->lhs->type) || !isPtrLike(e->type)) return false;
      return staticPtr(e->lhs, out);
    case NodeKind::Add:
    case NodeKind::Sub: {
      if (!isPtrLike(e->type) || e->rhs->kind != NodeKind::Num || !isPtrLike(e->lhs->type))
        return false;
      Loc b;
      if (!staticPtr(e->lhs, b)) return false;
      int64_t a = b.addr + (e->kind == NodeKind::Add ? e->rhs->ival : -e->rhs->ival);
      if (a < 0 || a > 0xFFFF) return false;
      out = Loc{b.kind, static_cast<int>(a)};
      return true;
    }
    case NodeKind::Member:
    case NodeKind::Deref:
      if (e->type->kind != TypeKind::Array) return false;
      return staticLoc(e, out);
    default:
      return false;
  }
}

// The location of an lvalue, if known at compile time.
bool CodeGen::staticLoc(Node* e, Loc& out) {
  switch (e->kind) {
    case NodeKind::Var:
      if (e->var->storage == Storage::Auto)
        out = Loc{Loc::Frame, e->var->address};
      else
        out = Loc{Loc::Global, e->var->address};
      return true;
    case NodeKind::Member: {
      Loc b;
      if (!staticLoc(e->lhs, b) || b.addr + e->offset > 0xFFFF) return false;
      out = Loc{b.kind, b.addr + e->offset};
      return true;
    }
    case NodeKind::Deref:
      return staticPtr(e->lhs, out);
    case NodeKind::Str:
      out = Loc{Loc::Global, stringAddress(e->str, e->pos)};
      return true;
    default:
      return false;
  }
}

// ===================================================================
// Functions.

vm::Image CodeGen::run() {
  // Start-up stub: CALL main; POP; HALT.
  int mainLine = prog_.main->defPos.line;
  emitU16(Op::CALL, 0, mainLine);
  callFixups_.emplace_back(1, prog_.main);
  emit(Op::POP, mainLine);
  emit(Op::HALT, mainLine);
  img_.entry = 0;

  for (Obj* g : prog_.globals) g->address = allocData(g->type->size, g->pos, "'" + g->name + "'");
  for (Obj* g : prog_.globals)
    if (g->init) {
      writeInit(g->init, g->address);
      markInitialised(g->address, g->type->size);
    }

  for (Function* f : prog_.functions) function(f);
  std::sort(img_.resumePoints.begin(), img_.resumePoints.end());
  if (Obj* const* t = prog_.timer.data(); t[0])
    img_.timer =
        vm::TimerBlock{static_cast<uint16_t>(t[0]->address), static_cast<uint16_t>(t[1]->address),
                       static_cast<uint16_t>(t[2]->address), static_cast<uint16_t>(t[3]->address)};

  for (auto [at, f] : callFixups_) {
    img_.code[static_cast<size_t>(at)] = static_cast<uint8_t>(f->address & 0xFF);
    img_.code[static_cast<size_t>(at) + 1] = static_cast<uint8_t>(f->address >> 8);
  }

  for (const IntVecBinding& b : prog_.vectors)
    img_.vectors.push_back(vm::VectorBinding{static_cast<uint8_t>(b.vector),
                                             static_cast<uint16_t>(b.handler->address),
                                             b.handler->name});

  // Symbols.
  using K = vm::Symbol::Kind;
  for (Function* f : prog_.functions)
    img_.symbols.push_back(vm::Symbol{f->name, f->isHandler ? K::Handler : K::Function,
                                      static_cast<uint32_t>(f->address),
                                      static_cast<uint32_t>(f->codeSize), typeName(f->type),
                                      vm::Symbol::Value::Code, f->defPos.line});
  for (Obj* g : prog_.globals)
    img_.symbols.push_back(vm::Symbol{g->name, K::Global, static_cast<uint32_t>(g->address),
                                      static_cast<uint32_t>(g->type->size), typeName(g->type),
                                      symbolValue(g->type), g->pos.line});
  for (Function* f : prog_.functions) {
    auto add = [&](Obj* o) {
      K kind = o->storage == Storage::Auto ? K::Auto : o->isParam ? K::Param : K::Static;
      img_.symbols.push_back(vm::Symbol{o->symName, kind, static_cast<uint32_t>(o->address),
                                        static_cast<uint32_t>(o->type->size), typeName(o->type),
                                        symbolValue(o->type), o->pos.line});
    };
    for (Obj* p : f->params) add(p);
    for (Obj* l : f->locals) add(l);
  }
  return std::move(img_);
}

void CodeGen::function(Function* f) {
  fn_ = f;
  f->address = static_cast<int>(img_.code.size());
  int line = f->defPos.line;
  curPos_ = f->defPos;

  // Storage: statics get data addresses now, autos frame offsets (packed,
  // parameters first, each block's locals after the enclosing ones').
  int frame = 0;
  auto place = [&](Obj* o) {
    if (o->storage == Storage::Auto) {
      o->address = frame;
      frame += o->type->size;
      if (frame > 0x7FFF) fail(o->pos, "too many local variables in '" + f->name + "'");
    } else {
      o->address = allocData(o->type->size, o->pos, "'" + o->symName + "'");
    }
  };
  for (Obj* p : f->params) place(p);
  for (Obj* l : f->locals) place(l);
  for (Obj* l : f->locals)
    if (l->storage == Storage::Static && l->init) {
      writeInit(l->init, l->address);
      markInitialised(l->address, l->type->size);
    }
  f->frameSize = frame;

  labels_.clear();
  userLabels_.clear();
  epilogue_ = newLabel();

  // Prologue: the frame, then the arguments popped in reverse order.
  if (frame > 0) emitU16(Op::ENTER, frame, line);
  for (auto it = f->params.rbegin(); it != f->params.rend(); ++it) {
    Obj* p = *it;
    Loc l =
        p->storage == Storage::Auto ? Loc{Loc::Frame, p->address} : Loc{Loc::Global, p->address};
    store(l, p->type, false, p->pos.line);
  }

  stmt(f->body);

  int endLine = f->body->endPos.line;
  bind(epilogue_);
  if (f->isHandler) {
    emit(Op::RETI, endLine);
  } else {
    pushConst(f->type->base->kind == TypeKind::Void ? tyInt() : f->type->base, 0, endLine);
    emit(Op::RET, endLine);
  }

  for (const Label& l : labels_) {
    for (int at : l.fixups) {
      int rel = l.addr - (at + 2);
      if (rel < -32768 || rel > 32767) fail(f->defPos, "function '" + f->name + "' is too large");
      img_.code[static_cast<size_t>(at)] = static_cast<uint8_t>(rel & 0xFF);
      img_.code[static_cast<size_t>(at) + 1] = static_cast<uint8_t>((rel >> 8) & 0xFF);
    }
  }
  f->codeSize = static_cast<int>(img_.code.size()) - f->address;
  fn_ = nullptr;
}

// Statements. Each one but a block (and a label, whose statement has its
// own) starts with the DBG hook in debug builds.
void CodeGen::stmt(Node* n) {
  int line = n->pos.line;
  curPos_ = n->pos;
  bool hook = n->kind != NodeKind::Block && n->kind != NodeKind::Case && n->kind != NodeKind::Label;
  if (hook && fn_->debug) emit(Op::DBG, line);

  switch (n->kind) {
    case NodeKind::Block:
      for (Node* s : n->list) stmt(s);
      return;
    case NodeKind::Empty:
      return;
    case NodeKind::ExprStmt:
      effect(n->lhs);
      return;
    case NodeKind::DeclInit:
      declInit(n);
      return;
    case NodeKind::If: {
      int lelse = newLabel();
      cond(n->cond, lelse, false);
      stmt(n->then);
      if (n->els) {
        int lend = newLabel();
        jump(Op::JMP, lend, n->then->pos.line);
        bind(lelse);
        stmt(n->els);
        bind(lend);
      } else {
        bind(lelse);
      }
      return;
    }
    case NodeKind::While: {
      int ltop = newLabel(), lend = newLabel();
      bind(ltop);
      cond(n->cond, lend, false);
      breaks_.push_back(lend);
      continues_.push_back(ltop);
      stmt(n->then);
      breaks_.pop_back();
      continues_.pop_back();
      jump(Op::JMP, ltop, line);
      bind(lend);
      return;
    }
    case NodeKind::DoWhile: {
      int ltop = newLabel(), lcont = newLabel(), lend = newLabel();
      bind(ltop);
      breaks_.push_back(lend);
      continues_.push_back(lcont);
      stmt(n->then);
      breaks_.pop_back();
      continues_.pop_back();
      bind(lcont);
      cond(n->cond, ltop, true);
      bind(lend);
      return;
    }
    case NodeKind::For: {
      if (n->init) {
        if (n->init->kind == NodeKind::ExprStmt)
          effect(n->init->lhs);
        else
          stmt(n->init);
      }
      int ltop = newLabel(), lcont = newLabel(), lend = newLabel();
      bind(ltop);
      const int top = static_cast<int>(img_.code.size());
      if (n->cond) cond(n->cond, lend, false);
      breaks_.push_back(lend);
      continues_.push_back(lcont);
      stmt(n->then);
      breaks_.pop_back();
      continues_.pop_back();
      bind(lcont);
      if (n->inc) effect(n->inc->lhs);
      jump(Op::JMP, ltop, line);
      bind(lend);
      if (isDelayLoop(n))
        img_.delayLoops.push_back(
            {static_cast<uint16_t>(top), static_cast<uint16_t>(img_.code.size())});
      return;
    }
    case NodeKind::Switch: {
      // The selector goes to a hidden static so each compare reloads it.
      const Type* t = n->cond->type;
      bool isLong = t->size == 4;
      int tmp = allocData(isLong ? 4 : 2, n->pos, "a switch temporary");
      value(n->cond);
      emitU16(isLong ? Op::STGL : Op::STGW, tmp, line);
      int deflt = -1;
      for (Node* c : n->cases) {
        c->label = newLabel();
        if (c->isDefault) {
          deflt = c->label;
          continue;
        }
        emitU16(isLong ? Op::LDGL : Op::LDGW, tmp, line);
        pushConst(t, c->ival, line);
        emit(isLong ? Op::EQL : Op::EQW, line);
        jump(Op::JNZ, c->label, line);
      }
      int lend = newLabel();
      jump(Op::JMP, deflt >= 0 ? deflt : lend, line);
      breaks_.push_back(lend);
      stmt(n->then);
      breaks_.pop_back();
      bind(lend);
      return;
    }
    case NodeKind::Case:
      bind(n->label);
      stmt(n->then);
      return;
    case NodeKind::Break:
      jump(Op::JMP, breaks_.back(), line);
      return;
    case NodeKind::Continue:
      jump(Op::JMP, continues_.back(), line);
      return;
    case NodeKind::Return: {
      if (fn_->isHandler) {
        jump(Op::JMP, epilogue_, line);
        return;
      }
      const Type* ret = fn_->type->base;
      if (n->lhs && ret->kind != TypeKind::Void) {
        value(n->lhs);
      } else {
        if (n->lhs) effect(n->lhs);
        pushConst(ret->kind == TypeKind::Void ? tyInt() : ret, 0, line);
      }
      emit(Op::RET, line);
      return;
    }
    case NodeKind::Goto: {
      auto it = userLabels_.find(n->str);
      int l = it != userLabels_.end() ? it->second : (userLabels_[n->str] = newLabel());
      jump(Op::JMP, l, line);
      return;
    }
    case NodeKind::Label: {
      auto it = userLabels_.find(n->str);
      int l = it != userLabels_.end() ? it->second : (userLabels_[n->str] = newLabel());
      bind(l);
      stmt(n->then);
      return;
    }
    case NodeKind::Costate:
      costate(n);
      return;
    case NodeKind::Waitfor:
      waitfor(n);
      return;
    case NodeKind::Yield: {
      const int resume = newLabel();
      costateYield(n->costate, resume, line);
      bindResumePoint(resume);
      return;
    }
    case NodeKind::Abort:
      costateClose(n->costate, line);
      jump(Op::JMP, n->costate->label, line);
      return;
    default:
      fail(n->pos, "internal error: unexpected statement");
  }
}

// A counting loop with nothing in it: `for (...; v < N; v++) ;` (or <=) on
// a static or global int, unsigned, long or unsigned long. The VM checks
// the code's shape too.
bool CodeGen::isDelayLoop(const Node* n) const {
  const Node* body = n->then;
  const bool empty =
      body->kind == NodeKind::Empty || (body->kind == NodeKind::Block && body->list.empty());
  if (!empty || !n->cond || !n->inc) return false;
  const Node* c = n->cond;
  if ((c->kind != NodeKind::Lt && c->kind != NodeKind::Le) || c->lhs->kind != NodeKind::Var ||
      c->rhs->kind != NodeKind::Num)
    return false;
  const Obj* v = c->lhs->var;
  if (v->storage != Storage::Global && v->storage != Storage::Static) return false;
  const TypeKind k = v->type->kind;
  if (k != TypeKind::Int && k != TypeKind::UInt && k != TypeKind::Long && k != TypeKind::ULong)
    return false;
  const Node* inc = n->inc->lhs;
  return inc->kind == NodeKind::IncDec && inc->delta == 1 && inc->lhs->kind == NodeKind::Var &&
         inc->lhs->var == v;
}

// costate { body }:
//         COSTATE cd, end      ; resume where it gave way, or from the top
//         body
//         COEND cd / CODONE cd ; its closing brace: next pass from the top
//   end:
void CodeGen::costate(Node* n) {
  const int line = n->pos.line;
  const int end = newLabel();
  n->label = end;
  coJump(Op::COSTATE, n->var->address, end, line);
  stmt(n->then);
  const int close = n->then->endPos.line;
  costateClose(n, close > 0 ? close : line);
  bind(end);
}

// The end of a costatement's pass (its closing brace or abort): the next
// pass starts at the top, and only an always_on one runs again by itself.
void CodeGen::costateClose(Node* costate, int line) {
  emitU16(costate->ival ? Op::COEND : Op::CODONE, costate->var->address, line);
}

// A place a costatement resumes at; the VM refuses any other.
void CodeGen::bindResumePoint(int label) {
  bind(label);
  img_.resumePoints.push_back(static_cast<uint16_t>(img_.code.size()));
}

// Gives way: lastlocADDR := resume, then leave through the costatement's end.
void CodeGen::costateYield(Node* costate, int resumeLabel, int line) {
  coJump(Op::COYIELD, costate->var->address, resumeLabel, line);
  jump(Op::JMP, costate->label, line);
}

// waitfor(expr):
//         firsttime := 1       ; reached afresh: a Delay function starts timing
//   test: expr, JNZ go         ; resumed here while it is false
//         COYIELD cd, test
//         JMP end
//   go:
void CodeGen::waitfor(Node* n) {
  const int line = n->pos.line;
  const int cd = n->costate->var->address;
  emitU16(Op::PUSHW, 1, line);
  emitU16(Op::STGB, cd + vm::kCoFirstTime, line);
  const int test = newLabel(), go = newLabel();
  bindResumePoint(test);
  cond(n->cond, go, true);
  costateYield(n->costate, test, line);
  bind(go);
}

// An auto variable's initialiser, run at each entry to its block.
void CodeGen::declInit(Node* n) {
  Obj* v = n->var;
  const Init* init = n->initv;
  int line = n->pos.line;
  const Type* t = v->type;
  if (init->expr && !isAggregate(t)) {
    storeValue(init->expr, t, false);
    store(Loc{Loc::Frame, v->address}, t, false, line);
    return;
  }
  bool partialString = init->expr && t->kind == TypeKind::Array &&
                       static_cast<int>(init->expr->str.size()) + 1 < t->arrayLen;
  if (!init->expr || partialString) {
    // Zero the whole object, then store the elements given.
    emitU16(Op::LEAL, v->address, line);
    emitU16(Op::PUSHW, 0, line);
    emitU16(Op::PUSHW, t->size, line);
    emitU16(Op::LIB, static_cast<int>(vm::Lib::MEMSET) | (3 << 8), line);
    emit(Op::POP, line);
  }
  autoInitStores(init, v->address, line);
}

void CodeGen::autoInitStores(const Init* init, int off, int line) {
  const Type* t = init->type;
  if (!init->expr) {
    for (size_t i = 0; i < init->children.size(); ++i) {
      int o = t->kind == TypeKind::Array ? off + static_cast<int>(i) * t->base->size
                                         : off + t->members[i].offset;
      autoInitStores(init->children[i], o, line);
    }
    return;
  }
  Node* e = init->expr;
  if (t->kind == TypeKind::Array) {  // char array from a string: memcpy from the literal
    int n = static_cast<int>(std::min(e->str.size() + 1, static_cast<size_t>(t->arrayLen)));
    emitU16(Op::LEAL, off, line);
    emitU16(Op::PUSHW, stringAddress(e->str, e->pos), line);
    emitU16(Op::PUSHW, n, line);
    emitU16(Op::LIB, static_cast<int>(vm::Lib::MEMCPY) | (3 << 8), line);
    emit(Op::POP, line);
    return;
  }
  if (isStructLike(t)) {
    emitU16(Op::LEAL, off, line);
    value(e);
    emitU16(Op::COPY, t->size, line);
    return;
  }
  if ((e->kind == NodeKind::Num && e->ival == 0) ||
      (e->kind == NodeKind::FNum && e->fval == 0 && !std::signbit(e->fval)))
    return;  // already zero
  storeValue(e, t, false);
  store(Loc{Loc::Frame, off}, t, false, line);
}

// ===================================================================
// Expressions.

void CodeGen::pushAddress(const Loc& l, int line) {
  if (l.kind == Loc::Global)
    emitU16(Op::PUSHW, l.addr, line);
  else if (l.kind == Loc::Frame)
    emitU16(Op::LEAL, l.addr, line);
}

void CodeGen::load(const Loc& l, const Type* t, int line) {
  if (isAggregate(t)) {  // the value of an array or struct is its address
    pushAddress(l, line);
    return;
  }
  Rep r = repOf(t);
  int w = r == Rep::Byte ? 0 : (r == Rep::WordS || r == Rep::WordU) ? 1 : 2;
  static constexpr Op g[] = {Op::LDGB, Op::LDGW, Op::LDGL};
  static constexpr Op f[] = {Op::LDLB, Op::LDLW, Op::LDLL};
  static constexpr Op s[] = {Op::LDIB, Op::LDIW, Op::LDIL};
  if (l.kind == Loc::Global)
    emitU16(g[w], l.addr, line);
  else if (l.kind == Loc::Frame)
    emitU16(f[w], l.addr, line);
  else
    emit(s[w], line);
}

// Stores the value on top; `keep` leaves it there (DUP or the STIxK form).
void CodeGen::store(const Loc& l, const Type* t, bool keep, int line) {
  Rep r = repOf(t);
  int w = r == Rep::Byte ? 0 : (r == Rep::WordS || r == Rep::WordU) ? 1 : 2;
  static constexpr Op g[] = {Op::STGB, Op::STGW, Op::STGL};
  static constexpr Op f[] = {Op::STLB, Op::STLW, Op::STLL};
  static constexpr Op s[] = {Op::STIB, Op::STIW, Op::STIL};
  static constexpr Op k[] = {Op::STIBK, Op::STIWK, Op::STILK};
  if (l.kind == Loc::Stack) {
    emit(keep ? k[w] : s[w], line);
    return;
  }
  if (keep) emit(Op::DUP, line);
  emitU16(l.kind == Loc::Global ? g[w] : f[w], l.addr, line);
}

Loc CodeGen::addr(Node* n) {
  int line = n->pos.line;
  Loc l;
  switch (n->kind) {
    case NodeKind::Var:
    case NodeKind::Str:
      staticLoc(n, l);
      return l;
    case NodeKind::Deref:
      if (staticPtr(n->lhs, l)) return l;
      value(n->lhs);
      return Loc{Loc::Stack, 0};
    case NodeKind::Member: {
      Loc b = addr(n->lhs);
      if (b.kind != Loc::Stack && b.addr + n->offset <= 0xFFFF)
        return Loc{b.kind, b.addr + n->offset};
      pushAddress(b, line);
      if (n->offset) {
        emitU16(Op::PUSHW, n->offset, line);
        emit(Op::ADDW, line);
      }
      return Loc{Loc::Stack, 0};
    }
    default:
      // A struct-valued expression (?:, assignment): its value is its address.
      value(n);
      return Loc{Loc::Stack, 0};
  }
}

// Representation change between two types' slots.
void CodeGen::convert(const Type* from, const Type* to, int line) {
  Rep a = repOf(from), b = repOf(to);
  if (a == b || a == Rep::Other || b == Rep::Other) return;
  auto isWord = [](Rep r) { return r == Rep::WordS || r == Rep::WordU; };
  auto isLong = [](Rep r) { return r == Rep::LongS || r == Rep::LongU; };
  if (b == Rep::Byte) {
    if (isLong(a)) emit(Op::L2W, line);
    if (a == Rep::Float) emit(Op::F2W, line);
    emit(Op::W2B, line);
  } else if (isWord(b)) {
    if (isLong(a))
      emit(Op::L2W, line);
    else if (a == Rep::Float)
      emit(Op::F2W, line);
  } else if (isLong(b)) {
    if (a == Rep::WordS)
      emit(Op::W2L, line);
    else if (a == Rep::Byte || a == Rep::WordU)
      emit(Op::UW2L, line);
    else if (a == Rep::Float)
      emit(b == Rep::LongS ? Op::F2L : Op::F2UL, line);
  } else if (b == Rep::Float) {
    if (a == Rep::WordS)
      emit(Op::W2F, line);
    else if (a == Rep::Byte || a == Rep::WordU)
      emit(Op::UW2F, line);
    else if (a == Rep::LongS)
      emit(Op::L2F, line);
    else if (a == Rep::LongU)
      emit(Op::UL2F, line);
  }
}

// The value to be stored into `target`. A byte store truncates by itself, so
// the W2B of a conversion to char is dropped unless the value is kept.
void CodeGen::storeValue(Node* rhs, const Type* target, bool keep) {
  if (!keep && target->kind == TypeKind::Char && rhs->kind == NodeKind::Cast &&
      (repOf(rhs->lhs->type) == Rep::WordS || repOf(rhs->lhs->type) == Rep::WordU)) {
    value(rhs->lhs);
    return;
  }
  value(rhs);
}

void CodeGen::arithOp(NodeKind k, const Type* t, int line) {
  Rep r = repOf(t);
  bool isF = r == Rep::Float, isL = r == Rep::LongS || r == Rep::LongU;
  bool uns = r == Rep::WordU || r == Rep::LongU || r == Rep::Byte;
  Op op;
  switch (k) {
    case NodeKind::Add:
      op = isF ? Op::ADDF : isL ? Op::ADDL : Op::ADDW;
      break;
    case NodeKind::Sub:
      op = isF ? Op::SUBF : isL ? Op::SUBL : Op::SUBW;
      break;
    case NodeKind::Mul:
      op = isF ? Op::MULF : isL ? Op::MULL : Op::MULW;
      break;
    case NodeKind::Div:
      op = isF ? Op::DIVF : isL ? (uns ? Op::DIVUL : Op::DIVL) : (uns ? Op::DIVUW : Op::DIVW);
      break;
    case NodeKind::Mod:
      op = isL ? (uns ? Op::MODUL : Op::MODL) : (uns ? Op::MODUW : Op::MODW);
      break;
    case NodeKind::BitAnd:
      op = isL ? Op::ANDL : Op::ANDW;
      break;
    case NodeKind::BitOr:
      op = isL ? Op::ORL : Op::ORW;
      break;
    case NodeKind::BitXor:
      op = isL ? Op::XORL : Op::XORW;
      break;
    case NodeKind::Shl:
      op = isL ? Op::SHLL : Op::SHLW;
      break;
    case NodeKind::Shr:
      op = isL ? (uns ? Op::SHRUL : Op::SHRL) : (uns ? Op::SHRUW : Op::SHRW);
      break;
    default:
      fail(curPos_, "internal error: bad arithmetic operator");
  }
  emit(op, line);
}

void CodeGen::compareOp(NodeKind k, const Type* t, int line) {
  Rep r = repOf(t);
  int idx = static_cast<int>(k) - static_cast<int>(NodeKind::Eq);  // Eq Ne Lt Le Gt Ge
  static constexpr Op w[] = {Op::EQW, Op::NEW, Op::LTW, Op::LEW, Op::GTW, Op::GEW};
  static constexpr Op wu[] = {Op::EQW, Op::NEW, Op::LTUW, Op::LEUW, Op::GTUW, Op::GEUW};
  static constexpr Op l[] = {Op::EQL, Op::NEL, Op::LTL, Op::LEL, Op::GTL, Op::GEL};
  static constexpr Op lu[] = {Op::EQL, Op::NEL, Op::LTUL, Op::LEUL, Op::GTUL, Op::GEUL};
  static constexpr Op f[] = {Op::EQF, Op::NEF, Op::LTF, Op::LEF, Op::GTF, Op::GEF};
  switch (r) {
    case Rep::WordS:
      emit(w[idx], line);
      break;
    case Rep::LongS:
      emit(l[idx], line);
      break;
    case Rep::LongU:
      emit(lu[idx], line);
      break;
    case Rep::Float:
      emit(f[idx], line);
      break;
    default:
      emit(wu[idx], line);
      break;
  }
}

// Pushes the value of an expression (one slot).
void CodeGen::value(Node* n) {
  int line = n->pos.line;
  curPos_ = n->pos;
  switch (n->kind) {
    case NodeKind::Num:
      pushConst(n->type, n->ival, line);
      return;
    case NodeKind::FNum:
      emitF32(Op::PUSHF, n->fval, line);
      return;
    case NodeKind::Str:
      emitU16(Op::PUSHW, stringAddress(n->str, n->pos), line);
      return;
    case NodeKind::Var:
    case NodeKind::Member:
    case NodeKind::Deref: {
      Loc l = addr(n);
      load(l, n->type, line);
      return;
    }
    case NodeKind::Addr: {
      Loc l;
      if (staticLoc(n->lhs, l)) {
        pushAddress(l, line);
        return;
      }
      l = addr(n->lhs);
      pushAddress(l, line);
      return;
    }
    case NodeKind::Cast:
      value(n->lhs);
      convert(n->lhs->type, n->type, line);
      return;
    case NodeKind::Add:
    case NodeKind::Sub:
      if (isPtrLike(n->type)) {
        Loc l;
        if (staticPtr(n, l)) {
          pushAddress(l, line);
          return;
        }
      }
      [[fallthrough]];
    case NodeKind::Mul:
    case NodeKind::Div:
    case NodeKind::Mod:
    case NodeKind::BitAnd:
    case NodeKind::BitOr:
    case NodeKind::BitXor:
    case NodeKind::Shl:
    case NodeKind::Shr:
      value(n->lhs);
      value(n->rhs);
      arithOp(n->kind, n->type, line);
      return;
    case NodeKind::Eq:
    case NodeKind::Ne:
    case NodeKind::Lt:
    case NodeKind::Le:
    case NodeKind::Gt:
    case NodeKind::Ge:
      value(n->lhs);
      value(n->rhs);
      compareOp(n->kind, n->lhs->type, line);
      return;
    case NodeKind::LogAnd:
    case NodeKind::LogOr: {
      int lfalse = newLabel(), lend = newLabel();
      cond(n, lfalse, false);
      emitU16(Op::PUSHW, 1, line);
      jump(Op::JMP, lend, line);
      bind(lfalse);
      emitU16(Op::PUSHW, 0, line);
      bind(lend);
      return;
    }
    case NodeKind::Not: {
      value(n->lhs);
      Rep r = repOf(n->lhs->type);
      if (r == Rep::LongS || r == Rep::LongU)
        emit(Op::TESTL, line);
      else if (r == Rep::Float)
        emit(Op::TESTF, line);
      emit(Op::LNOTW, line);
      return;
    }
    case NodeKind::BitNot:
      value(n->lhs);
      emit(n->type->size == 4 ? Op::NOTL : Op::NOTW, line);
      return;
    case NodeKind::Neg: {
      value(n->lhs);
      Rep r = repOf(n->type);
      emit(r == Rep::Float                        ? Op::NEGF
           : (r == Rep::LongS || r == Rep::LongU) ? Op::NEGL
                                                  : Op::NEGW,
           line);
      return;
    }
    case NodeKind::Assign:
      assign(n, true);
      return;
    case NodeKind::OpAssign:
      opAssign(n, true);
      return;
    case NodeKind::IncDec:
      incDec(n, true);
      return;
    case NodeKind::Cond: {
      int lelse = newLabel(), lend = newLabel();
      cond(n->cond, lelse, false);
      value(n->lhs);
      jump(Op::JMP, lend, line);
      bind(lelse);
      value(n->rhs);
      bind(lend);
      return;
    }
    case NodeKind::Comma:
      effect(n->lhs);
      value(n->rhs);
      return;
    case NodeKind::Call:
      call(n);
      return;
    case NodeKind::LibCall:
      libCall(n);
      return;
    default:
      fail(n->pos, "internal error: expression has no value");
  }
}

// Evaluates an expression for its side effects only; leaves nothing.
void CodeGen::effect(Node* n) {
  int line = n->pos.line;
  curPos_ = n->pos;
  switch (n->kind) {
    case NodeKind::Num:
    case NodeKind::FNum:
    case NodeKind::Str:
    case NodeKind::Var:
      return;
    case NodeKind::Assign:
      assign(n, false);
      return;
    case NodeKind::OpAssign:
      if (!superInstruction(n)) opAssign(n, false);
      return;
    case NodeKind::IncDec:
      if (!superInstruction(n)) incDec(n, false);
      return;
    case NodeKind::Call:
      call(n);
      emit(Op::POP, line);
      return;
    case NodeKind::LibCall:
      libCall(n);
      if (n->type->kind != TypeKind::Void) emit(Op::POP, line);
      return;
    case NodeKind::Intrinsic:
      emit(n->lib == 0 ? Op::EI : Op::DI, line);
      return;
    case NodeKind::Comma:
      effect(n->lhs);
      effect(n->rhs);
      return;
    case NodeKind::Cast:
      effect(n->lhs);
      return;
    case NodeKind::Cond: {
      int lelse = newLabel(), lend = newLabel();
      cond(n->cond, lelse, false);
      effect(n->lhs);
      jump(Op::JMP, lend, line);
      bind(lelse);
      effect(n->rhs);
      bind(lend);
      return;
    }
    case NodeKind::LogAnd:
    case NodeKind::LogOr: {
      int lend = newLabel();
      cond(n->lhs, lend, n->kind == NodeKind::LogOr);
      effect(n->rhs);
      bind(lend);
      return;
    }
    default:
      value(n);
      emit(Op::POP, line);
      return;
  }
}

// Jumps to `label` if the truth of `n` equals `jumpIf`; falls through if not.
void CodeGen::cond(Node* n, int label, bool jumpIf) {
  int line = n->pos.line;
  curPos_ = n->pos;
  switch (n->kind) {
    case NodeKind::LogAnd:
    case NodeKind::LogOr: {
      bool isAnd = n->kind == NodeKind::LogAnd;
      if (jumpIf != isAnd) {  // and/false, or/true: either operand decides
        cond(n->lhs, label, jumpIf);
        cond(n->rhs, label, jumpIf);
      } else {
        int skip = newLabel();
        cond(n->lhs, skip, !jumpIf);
        cond(n->rhs, label, jumpIf);
        bind(skip);
      }
      return;
    }
    case NodeKind::Not:
      cond(n->lhs, label, !jumpIf);
      return;
    case NodeKind::Num:
    case NodeKind::FNum: {
      bool t = n->kind == NodeKind::Num ? n->ival != 0 : n->fval != 0;
      if (t == jumpIf) jump(Op::JMP, label, line);
      return;
    }
    default: {
      value(n);
      Rep r = repOf(n->type);
      if (r == Rep::LongS || r == Rep::LongU)
        emit(Op::TESTL, line);
      else if (r == Rep::Float)
        emit(Op::TESTF, line);
      jump(jumpIf ? Op::JNZ : Op::JZ, label, line);
      return;
    }
  }
}

void CodeGen::assign(Node* n, bool keep) {
  int line = n->pos.line;
  const Type* t = n->lhs->type;
  if (isStructLike(t)) {
    Loc d = addr(n->lhs);
    pushAddress(d, line);
    if (keep) emit(Op::DUP, line);
    value(n->rhs);
    emitU16(Op::COPY, t->size, line);
    return;
  }
  Loc l = addr(n->lhs);
  storeValue(n->rhs, t, keep);
  store(l, t, keep, line);
}

void CodeGen::opAssign(Node* n, bool keep) {
  int line = n->pos.line;
  const Type* t = n->lhs->type;
  Loc l = addr(n->lhs);
  if (l.kind == Loc::Stack) emit(Op::DUP, line);
  load(l, t, line);
  convert(t, n->opType, line);
  value(n->rhs);
  arithOp(n->op, n->opType, line);
  if (!(t->kind == TypeKind::Char && !keep && repOf(n->opType) != Rep::Float &&
        repOf(n->opType) != Rep::LongS && repOf(n->opType) != Rep::LongU))
    convert(n->opType, t, line);
  store(l, t, keep, line);
}

void CodeGen::incDec(Node* n, bool keep) {
  int line = n->pos.line;
  const Type* t = n->lhs->type;
  Loc l = addr(n->lhs);
  int amount = n->delta < 0 ? -n->delta : n->delta;
  Op add = n->delta < 0 ? Op::SUBW : Op::ADDW;
  Rep r = repOf(t);
  if (r == Rep::LongS || r == Rep::LongU) add = n->delta < 0 ? Op::SUBL : Op::ADDL;
  if (r == Rep::Float) add = n->delta < 0 ? Op::SUBF : Op::ADDF;
  auto step = [&]() {
    if (r == Rep::Float)
      emitF32(Op::PUSHF, static_cast<float>(amount), line);
    else
      pushConst(t, amount, line);
    emit(add, line);
  };
  if (!keep || n->prefix) {
    if (l.kind == Loc::Stack) emit(Op::DUP, line);
    load(l, t, line);
    step();
    if (keep && r == Rep::Byte) emit(Op::W2B, line);
    store(l, t, keep, line);
    return;
  }
  // Postfix with its (old) value used.
  if (l.kind == Loc::Stack) {
    emit(Op::DUP, line);   // addr addr
    load(l, t, line);      // addr old
    emit(Op::TUCK, line);  // old addr old
    step();                // old addr new
    store(l, t, false, line);
    return;
  }
  load(l, t, line);
  emit(Op::DUP, line);
  step();
  store(l, t, false, line);
}

// x++, ++x, x += 1, x--, --x, x -= 1 as statements on a 16-bit static:
// INCGW/DECGW; x++/++x/x += 1 on a 32-bit static: INCGL.
bool CodeGen::superInstruction(Node* n) {
  Node* l = n->lhs;
  if (l->kind != NodeKind::Var || l->var->storage == Storage::Auto) return false;
  int delta;
  if (n->kind == NodeKind::IncDec) {
    delta = n->delta;
  } else {
    if ((n->op != NodeKind::Add && n->op != NodeKind::Sub) || n->rhs->kind != NodeKind::Num ||
        n->rhs->ival != 1 || isPtrLike(l->type))
      return false;
    delta = n->op == NodeKind::Add ? 1 : -1;
  }
  int line = n->pos.line;
  TypeKind k = l->type->kind;
  if ((k == TypeKind::Int || k == TypeKind::UInt) && (delta == 1 || delta == -1)) {
    emitU16(delta == 1 ? Op::INCGW : Op::DECGW, l->var->address, line);
    return true;
  }
  if ((k == TypeKind::Long || k == TypeKind::ULong) && delta == 1) {
    emitU16(Op::INCGL, l->var->address, line);
    return true;
  }
  return false;
}

void CodeGen::call(Node* n) {
  for (Node* a : n->list) value(a);
  int line = n->pos.line;
  curPos_ = n->pos;
  emitU16(Op::CALL, 0, line);
  callFixups_.emplace_back(static_cast<int>(img_.code.size()) - 2, n->callee);
}

void CodeGen::libCall(Node* n) {
  for (Node* a : n->list) value(a);
  int line = n->pos.line;
  curPos_ = n->pos;
  if (n->list.size() > static_cast<size_t>(vm::kMaxLibArgs))
    fail(n->pos,
         "too many arguments to a library call (at most " + std::to_string(vm::kMaxLibArgs) + ")");
  emitU16(Op::LIB, n->lib | (static_cast<int>(n->list.size()) << 8), line);
}

}  // namespace

vm::Image generate(Program& prog) { return CodeGen(prog).run(); }

}  // namespace simbot::compiler
