// The image's type table (vm::TypeInfo): what a reader of robot memory
// needs to take a variable apart (the debugger's print, --watch of a
// member or an element), built from the compiler's types after layout. A
// struct is entered before its members so that a member pointing back at
// it (a list node) names the entry being built.
#include <unordered_map>

#include "compiler/codegen_impl.h"

namespace simbot::compiler::detail {

namespace {

using K = vm::TypeInfo::Kind;

K kindOf(const Type* t) {
  switch (t->kind) {
    case TypeKind::Void:
      return K::Void;
    case TypeKind::Ptr:
      return K::Pointer;
    case TypeKind::Array:
      return K::Array;
    case TypeKind::Struct:
      return K::Struct;
    case TypeKind::Union:
      return K::Union;
    case TypeKind::Func:
      return K::Function;
    default:
      return K::Scalar;
  }
}

}  // namespace

int32_t DebugTypes::id(const Type* t) {
  if (!t) return -1;
  if (auto it = ids_.find(t); it != ids_.end()) return it->second;
  const auto index = static_cast<int32_t>(types_.size());
  ids_[t] = index;
  vm::TypeInfo info;
  info.kind = kindOf(t);
  info.size = static_cast<uint32_t>(std::max(t->size, 0));
  info.name = typeName(t);
  if (info.kind == K::Scalar || info.kind == K::Pointer) info.scalar = symbolValue(t);
  types_.push_back(std::move(info));
  // Later entries may move the table: fill this one by index.
  int32_t base = -1;
  if (t->base &&
      (t->kind == TypeKind::Ptr || t->kind == TypeKind::Array || t->kind == TypeKind::Func))
    base = id(t->base);
  types_[static_cast<size_t>(index)].base = base;
  if (t->kind == TypeKind::Array)
    types_[static_cast<size_t>(index)].count = std::max(t->arrayLen, 0);
  if (t->kind == TypeKind::Struct || t->kind == TypeKind::Union) {
    std::vector<vm::TypeInfo::Field> fields;
    for (const Member& m : t->members)
      fields.push_back({m.name, static_cast<uint32_t>(m.offset), id(m.type)});
    types_[static_cast<size_t>(index)].fields = std::move(fields);
  }
  return index;
}

}  // namespace simbot::compiler::detail
