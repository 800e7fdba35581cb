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
//
// This file: emission, data layout, functions and statements; expressions
// are in gen_expr.cpp (codegen_impl.h).
#include "compiler/codegen_impl.h"

namespace simbot::compiler {

namespace detail {

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
  const Node* f = e;
  while (f->kind == NodeKind::Cast && isPtrLike(f->type) && isPtrLike(f->lhs->type)) f = f->lhs;
  if (t->size == 2 && f->kind == NodeKind::FuncRef) {  // written once functions are laid out
    dataFixups_.emplace_back(a, f->callee);
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
  for (auto [at, f] : dataFixups_) writeData(at, static_cast<uint64_t>(f->address), 2);
  // What a call through a pointer may reach: each function's entry and how
  // many arguments its prologue pops (handlers are not callable).
  for (Function* f : prog_.functions)
    if (!f->isHandler)
      img_.entries.push_back(vm::Image::Entry{static_cast<uint16_t>(f->address),
                                              static_cast<uint8_t>(f->params.size())});
  std::sort(
      img_.entries.begin(), img_.entries.end(),
      [](const vm::Image::Entry& a, const vm::Image::Entry& b) { return a.address < b.address; });

  for (const IntVecBinding& b : prog_.vectors)
    img_.vectors.push_back(vm::VectorBinding{static_cast<uint8_t>(b.vector),
                                             static_cast<uint16_t>(b.handler->address),
                                             b.handler->name});

  // Symbols.
  using K = vm::Symbol::Kind;
  DebugTypes types;
  for (Function* f : prog_.functions)
    img_.symbols.push_back(vm::Symbol{f->name, f->isHandler ? K::Handler : K::Function,
                                      static_cast<uint32_t>(f->address),
                                      static_cast<uint32_t>(f->codeSize), typeName(f->type),
                                      vm::Symbol::Value::Code, f->defPos.line});
  for (Obj* g : prog_.globals)
    img_.symbols.push_back(vm::Symbol{g->name, K::Global, static_cast<uint32_t>(g->address),
                                      static_cast<uint32_t>(g->type->size), typeName(g->type),
                                      symbolValue(g->type), g->pos.line, types.id(g->type)});
  for (Function* f : prog_.functions) {
    auto add = [&](Obj* o) {
      K kind = o->storage == Storage::Auto ? K::Auto : o->isParam ? K::Param : K::Static;
      img_.symbols.push_back(vm::Symbol{o->symName, kind, static_cast<uint32_t>(o->address),
                                        static_cast<uint32_t>(o->type->size), typeName(o->type),
                                        symbolValue(o->type), o->pos.line, types.id(o->type),
                                        o->storage == Storage::Auto ? o->scopeEnd : 0, o->isParam});
    };
    for (Obj* p : f->params) add(p);
    for (Obj* l : f->locals) add(l);
  }
  img_.types = types.take();
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

}  // namespace detail

vm::Image generate(Program& prog) { return detail::CodeGen(prog).run(); }

}  // namespace simbot::compiler
