// compiler/gen_expr.cpp -- the code generator's expressions (codegen_impl.h):
// addresses, loads and stores, conversions, operators, conditions that jump
// directly, assignments, increments, calls.
#include "compiler/codegen_impl.h"

namespace simbot::compiler::detail {

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
  int w = widthIndex(r);
  static constexpr Op g[] = {Op::LDGB, Op::LDGW, Op::LDGL};
  static constexpr Op f[] = {Op::LDLB, Op::LDLW, Op::LDLL};
  static constexpr Op s[] = {Op::LDIB, Op::LDIW, Op::LDIL};
  if (l.kind == Loc::Global)
    emitU16(g[w], l.addr, line);
  else if (l.kind == Loc::Frame)
    emitU16(f[w], l.addr, line);
  else
    emit(s[w], line);
  if (r == Rep::ByteS) emit(Op::SXB, line);
}

// Stores the value on top; `keep` leaves it there (DUP or the STIxK form).
void CodeGen::store(const Loc& l, const Type* t, bool keep, int line) {
  Rep r = repOf(t);
  int w = widthIndex(r);
  static constexpr Op g[] = {Op::STGB, Op::STGW, Op::STGL};
  static constexpr Op f[] = {Op::STLB, Op::STLW, Op::STLL};
  static constexpr Op s[] = {Op::STIB, Op::STIW, Op::STIL};
  static constexpr Op k[] = {Op::STIBK, Op::STIWK, Op::STILK};
  if (l.kind == Loc::Stack) {
    emit(keep ? k[w] : s[w], line);
    // STIBK keeps the stored byte zero-extended; a signed char's value is
    // its sign extension.
    if (keep && r == Rep::ByteS) emit(Op::SXB, line);
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
      if (staticPtr(n->lhs, l)) return accessible(l, n->type, line);
      value(n->lhs);
      return Loc{Loc::Stack, 0};
    case NodeKind::Member: {
      Loc b = addr(n->lhs);
      if (b.kind != Loc::Stack && b.addr + n->offset <= 0xFFFF)
        return accessible(Loc{b.kind, b.addr + n->offset}, n->type, line);
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

// A constant address that an access of `t` would fault at (the null page,
// or past the end of memory: *(char *)5, *(int *)0xFFFF) goes the
// pointer's way, whose access faults at run time as a pointer variable's
// does; an absolute LDG/STG would read or write it without a word.
Loc CodeGen::accessible(Loc l, const Type* t, int line) {
  if (l.kind != Loc::Global || isAggregate(t)) return l;
  if (l.addr >= vm::kNullPageEnd && l.addr + t->size <= static_cast<int>(vm::kMemorySize)) return l;
  pushAddress(l, line);
  return Loc{Loc::Stack, 0};
}

// Representation change between two types' slots.
void CodeGen::convert(const Type* from, const Type* to, int line) {
  Rep a = repOf(from), b = repOf(to);
  if (a == b || a == Rep::Other || b == Rep::Other) return;
  auto isWord = [](Rep r) { return r == Rep::WordS || r == Rep::WordU; };
  auto isLong = [](Rep r) { return r == Rep::LongS || r == Rep::LongU; };
  if (b == Rep::Byte || b == Rep::ByteS) {
    if (isLong(a)) emit(Op::L2W, line);
    if (a == Rep::Float) emit(Op::F2W, line);
    emit(b == Rep::Byte ? Op::W2B : Op::SXB, line);
  } else if (isWord(b)) {
    if (isLong(a))
      emit(Op::L2W, line);
    else if (a == Rep::Float)
      emit(Op::F2W, line);
  } else if (isLong(b)) {
    if (a == Rep::WordS || a == Rep::ByteS)
      emit(Op::W2L, line);
    else if (a == Rep::Byte || a == Rep::WordU)
      emit(Op::UW2L, line);
    else if (a == Rep::Float)
      emit(b == Rep::LongS ? Op::F2L : Op::F2UL, line);
  } else if (b == Rep::Float) {
    if (a == Rep::WordS || a == Rep::ByteS)
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
  if (!keep && slotOf(target) == Slot::Byte && rhs->kind == NodeKind::Cast &&
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
    case NodeKind::FuncRef:
      emitU16(Op::PUSHW, 0, line);  // the address once functions are laid out
      callFixups_.emplace_back(static_cast<int>(img_.code.size()) - 2, n->callee);
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
    case NodeKind::FuncRef:
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
  if (!(slotOf(t) == Slot::Byte && !keep && repOf(n->opType) != Rep::Float &&
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
    if (keep && r == Rep::ByteS) emit(Op::SXB, line);
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
  if (!n->callee) {  // through a pointer: its value last, on top
    value(n->lhs);
    curPos_ = n->pos;
    emit(Op::CALLI, line);
    emitByte(static_cast<uint8_t>(n->list.size()), line);
    return;
  }
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

}  // namespace simbot::compiler::detail
