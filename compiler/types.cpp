// C types of Dynamic C on the Z180: char is 8-bit unsigned, short and int
// 16-bit, long 32-bit, float IEEE single, pointers 16-bit. Helpers to classify
// them and to spell them in symbols and messages.
#include <string>

#include "compiler/ast.h"

namespace simbot::compiler {

namespace {
Type makeBasic(TypeKind k, int size) {
  Type t;
  t.kind = k;
  t.size = size;
  return t;
}
Type gVoid = makeBasic(TypeKind::Void, 1);
Type gChar = makeBasic(TypeKind::Char, 1);
Type gInt = makeBasic(TypeKind::Int, 2);
Type gUInt = makeBasic(TypeKind::UInt, 2);
Type gLong = makeBasic(TypeKind::Long, 4);
Type gULong = makeBasic(TypeKind::ULong, 4);
Type gFloat = makeBasic(TypeKind::Float, 4);
}  // namespace

Type* tyVoid() { return &gVoid; }
Type* tyChar() { return &gChar; }
Type* tyInt() { return &gInt; }
Type* tyUInt() { return &gUInt; }
Type* tyLong() { return &gLong; }
Type* tyULong() { return &gULong; }
Type* tyFloat() { return &gFloat; }

bool isInteger(const Type* t) {
  switch (t->kind) {
    case TypeKind::Char:
    case TypeKind::Int:
    case TypeKind::UInt:
    case TypeKind::Long:
    case TypeKind::ULong:
      return true;
    default:
      return false;
  }
}
bool isArith(const Type* t) { return isInteger(t) || t->kind == TypeKind::Float; }
bool isPtrLike(const Type* t) { return t->kind == TypeKind::Ptr || t->kind == TypeKind::Array; }
bool isScalar(const Type* t) { return isArith(t) || isPtrLike(t); }
bool isStructLike(const Type* t) {
  return t->kind == TypeKind::Struct || t->kind == TypeKind::Union;
}
bool isUnsigned(const Type* t) {
  return t->kind == TypeKind::Char || t->kind == TypeKind::UInt || t->kind == TypeKind::ULong ||
         isPtrLike(t);
}

bool sameType(const Type* a, const Type* b) {
  if (a == b) return true;
  if (a->kind != b->kind) return false;
  switch (a->kind) {
    case TypeKind::Ptr:
      return sameType(a->base, b->base);
    case TypeKind::Array:
      return (a->arrayLen < 0 || b->arrayLen < 0 || a->arrayLen == b->arrayLen) &&
             sameType(a->base, b->base);
    case TypeKind::Struct:
    case TypeKind::Union:
      return false;  // distinct objects are distinct types
    case TypeKind::Func:
      if (!sameType(a->base, b->base)) return false;
      if (!a->hasProto || !b->hasProto) return true;
      if (a->params.size() != b->params.size()) return false;
      for (size_t i = 0; i < a->params.size(); ++i)
        if (!sameType(a->params[i].type, b->params[i].type)) return false;
      return true;
    default:
      return true;
  }
}

Slot slotOf(const Type* t) {
  switch (t->kind) {
    case TypeKind::Char:
      return Slot::Byte;
    case TypeKind::Int:
    case TypeKind::UInt:
    case TypeKind::Ptr:
    case TypeKind::Array:
      return Slot::Word;
    case TypeKind::Long:
    case TypeKind::ULong:
      return Slot::Long;
    case TypeKind::Float:
      return Slot::Float;
    case TypeKind::Struct:
    case TypeKind::Union:
      return Slot::Struct;
    default:
      return Slot::None;
  }
}

std::string slotName(const Type* t) {
  switch (slotOf(t)) {
    case Slot::Byte:
    case Slot::Word:
      return "16-bit";
    case Slot::Long:
      return "32-bit";
    case Slot::Float:
      return "float";
    default:
      return typeName(t);
  }
}

std::string typeName(const Type* t) {
  switch (t->kind) {
    case TypeKind::Void:
      return "void";
    case TypeKind::Char:
      return "char";
    case TypeKind::Int:
      return "int";
    case TypeKind::UInt:
      return "unsigned int";
    case TypeKind::Long:
      return "long";
    case TypeKind::ULong:
      return "unsigned long";
    case TypeKind::Float:
      return "float";
    case TypeKind::Ptr: {
      std::string b = typeName(t->base);
      return b + (b.back() == '*' ? "*" : " *");
    }
    case TypeKind::Array: {
      std::string dims;
      const Type* e = t;
      for (; e->kind == TypeKind::Array; e = e->base)
        dims += "[" + (e->arrayLen < 0 ? std::string() : std::to_string(e->arrayLen)) + "]";
      return typeName(e) + dims;
    }
    case TypeKind::Func:
      return typeName(t->base) + " ()";
    case TypeKind::Struct:
      return "struct " + (t->tag.empty() ? "<anonymous>" : t->tag);
    case TypeKind::Union:
      return "union " + (t->tag.empty() ? "<anonymous>" : t->tag);
  }
  return "?";
}

std::string typeCategory(const Type* t) {
  if (isPtrLike(t)) return "pointer";
  if (t->kind == TypeKind::Struct) return "struct";
  if (t->kind == TypeKind::Union) return "union";
  return typeName(t);
}

}  // namespace simbot::compiler
