// inspect/types.cpp -- the types of the debugger's values (types.h): the
// image's table with the basic types after it, and reading scalars from
// robot memory.
#include "inspect/types.h"

#include <fmt/format.h>

#include <array>
#include <bit>

namespace simbot::inspect {

using vm::Symbol;
using vm::TypeInfo;

namespace {

vm::Symbol::Value symbolValue(Arith a) {
  switch (a) {
    case Arith::Char:
      return Symbol::Value::Char;
    case Arith::SChar:
      return Symbol::Value::SChar;
    case Arith::Int:
      return Symbol::Value::Int;
    case Arith::UInt:
      return Symbol::Value::UInt;
    case Arith::Long:
      return Symbol::Value::Long;
    case Arith::ULong:
      return Symbol::Value::ULong;
    case Arith::Float:
      return Symbol::Value::Float;
  }
  return Symbol::Value::Int;
}

TypeInfo basic(Arith a, const char* name) {
  TypeInfo t;
  t.kind = TypeInfo::Kind::Scalar;
  t.scalar = symbolValue(a);
  t.size = static_cast<uint32_t>(compiler::arithSize(a));
  t.name = name;
  return t;
}

// After the image's table: void, then the arithmetic types in Arith's order.
const std::array<TypeInfo, 8>& basics() {
  static const std::array<TypeInfo, 8> kBasics = [] {
    TypeInfo v;
    v.kind = TypeInfo::Kind::Void;
    v.size = 1;
    v.name = "void";
    return std::array<TypeInfo, 8>{v,
                                   basic(Arith::Char, "char"),
                                   basic(Arith::SChar, "signed char"),
                                   basic(Arith::Int, "int"),
                                   basic(Arith::UInt, "unsigned int"),
                                   basic(Arith::Long, "long"),
                                   basic(Arith::ULong, "unsigned long"),
                                   basic(Arith::Float, "float")};
  }();
  return kBasics;
}

int32_t tableSize(const vm::Image& image) { return static_cast<int32_t>(image.types.size()); }

}  // namespace

const TypeInfo& typeOf(const vm::Image& image, int32_t type) {
  const int32_t n = tableSize(image);
  if (type >= 0 && type < n) return image.types[static_cast<size_t>(type)];
  if (type >= n && type < n + static_cast<int32_t>(basics().size()))
    return basics()[static_cast<size_t>(type - n)];
  throw Error("a value without a type");
}

int32_t voidType(const vm::Image& image) { return tableSize(image); }

int32_t basicType(const vm::Image& image, Arith a) {
  return tableSize(image) + 1 + static_cast<int32_t>(a);
}

std::optional<Arith> arithOf(const vm::Image& image, int32_t type) {
  const TypeInfo& t = typeOf(image, type);
  if (t.kind != TypeInfo::Kind::Scalar) return std::nullopt;
  switch (t.scalar) {
    case Symbol::Value::Char:
      return Arith::Char;
    case Symbol::Value::SChar:
      return Arith::SChar;
    case Symbol::Value::Int:
      return Arith::Int;
    case Symbol::Value::UInt:
      return Arith::UInt;
    case Symbol::Value::Long:
      return Arith::Long;
    case Symbol::Value::ULong:
      return Arith::ULong;
    case Symbol::Value::Float:
      return Arith::Float;
    default:
      return std::nullopt;
  }
}

bool sameType(const vm::Image& image, int32_t a, int32_t b) {
  // Pointer chains are short (the compiler caps derivations at 64).
  for (int depth = 0; depth < 100; ++depth) {
    if (a == b) return true;
    if (a < 0 || b < 0) return false;
    const TypeInfo& x = typeOf(image, a);
    const TypeInfo& y = typeOf(image, b);
    if (x.kind != y.kind) return false;
    switch (x.kind) {
      case TypeInfo::Kind::Void:
        return true;
      case TypeInfo::Kind::Scalar:
        return x.scalar == y.scalar;
      case TypeInfo::Kind::Pointer:
        a = x.base;
        b = y.base;
        continue;
      case TypeInfo::Kind::Array:
        if (x.count != y.count) return false;
        a = x.base;
        b = y.base;
        continue;
      default:
        return false;  // distinct structs, unions and functions are distinct
    }
  }
  return false;
}

int32_t pointerTypeTo(const vm::Image& image, int32_t target) {
  for (int32_t k = 0; k < tableSize(image); ++k) {
    const TypeInfo& t = image.types[static_cast<size_t>(k)];
    if (t.kind == TypeInfo::Kind::Pointer && sameType(image, t.base, target)) return k;
  }
  return -1;
}

std::string pointerName(const vm::Image& image, int32_t target) {
  const TypeInfo& t = typeOf(image, target);
  const std::string& name = t.name;
  if (t.kind == TypeInfo::Kind::Array) {
    const auto bracket = name.find('[');
    return name.substr(0, bracket) + " (*)" + name.substr(bracket);
  }
  if (t.kind == TypeInfo::Kind::Function && name.size() > 3 &&
      name.compare(name.size() - 3, 3, " ()") == 0)
    return name.substr(0, name.size() - 3) + " (*)()";
  return name + (!name.empty() && name.back() == '*' ? "*" : " *");
}

Resolved resolve(const vm::Image& image, const TypeName& name) {
  int32_t base = -1;
  if (name.isVoid) {
    base = voidType(image);
  } else if (!name.tag.empty()) {
    const bool isUnion = name.tag.rfind("union ", 0) == 0;
    for (int32_t k = 0; k < tableSize(image) && base < 0; ++k) {
      const TypeInfo& t = image.types[static_cast<size_t>(k)];
      if (t.kind == (isUnion ? TypeInfo::Kind::Union : TypeInfo::Kind::Struct) &&
          t.name == name.tag)
        base = k;
    }
    if (base < 0) throw Error(fmt::format("no '{}' in the program", name.tag));
  } else {
    base = basicType(image, name.arith);
  }
  if (name.pointers == 0) return Resolved{base, -1};
  // A pointer's target: the base, or a pointer type the program has.
  int32_t target = base;
  TypeName spelled = name;
  for (int k = 1; k < name.pointers; ++k) {
    spelled.pointers = k;
    target = pointerTypeTo(image, target);
    if (target < 0)
      throw Error(fmt::format("no type '{}' in the program to point at", spelled.text()));
  }
  return Resolved{-1, target};
}

Value integerValue(const vm::Image& image, Arith a, int64_t v) {
  Value out;
  out.type = basicType(image, a);
  out.integer = compiler::wrapArith(v, a);
  return out;
}

Value floatValue(const vm::Image& image, float f) {
  Value out;
  out.type = basicType(image, Arith::Float);
  out.real = f;
  return out;
}

Value addressValue(int32_t pointee, int64_t address) {
  Value out;
  out.pointee = pointee;
  out.integer = static_cast<int64_t>(static_cast<uint64_t>(address) & 0xFFFF);
  return out;
}

Value unknownOf(Value v) {
  v.known = false;
  v.integer = 0;
  v.real = 0;
  return v;
}

Value load(const Scope& s, const Value& object) {
  const vm::Image& image = s.image();
  const TypeInfo& t = typeOf(image, object.type);
  Value out;
  if (t.kind == TypeInfo::Kind::Pointer) {
    out = addressValue(t.base >= 0 ? t.base : voidType(image), 0);
  } else if (const std::optional<Arith> a = arithOf(image, object.type)) {
    out.type = basicType(image, *a);
  } else {
    throw Error("not a number: " + t.name);
  }
  if (!object.known || !s.vm) return unknownOf(out);
  const vm::Vm& m = *s.vm;
  const uint16_t at = object.address;
  switch (t.scalar) {
    case Symbol::Value::Char:
      out.integer = m.read8(at);
      break;
    case Symbol::Value::SChar:
      out.integer = static_cast<int8_t>(m.read8(at));
      break;
    case Symbol::Value::Int:
      out.integer = static_cast<int16_t>(m.read16(at));
      break;
    case Symbol::Value::Long:
      out.integer = static_cast<int32_t>(m.read32(at));
      break;
    case Symbol::Value::ULong:
      out.integer = m.read32(at);
      break;
    case Symbol::Value::Float:
      out.real = std::bit_cast<float>(m.read32(at));
      break;
    default:  // unsigned int, pointers
      out.integer = m.read16(at);
      break;
  }
  return out;
}

Value rvalue(const Scope& s, const Value& v) {
  if (v.anyType || !v.inMemory) return v;
  const TypeInfo& t = typeOf(s.image(), v.type);
  if (v.count > 0 || t.kind == TypeInfo::Kind::Array) {
    // An array (or a slice) is the address of its first element.
    Value out = addressValue(v.count > 0 ? v.type : t.base, v.address);
    return v.known ? out : unknownOf(out);
  }
  if (t.kind == TypeInfo::Kind::Scalar || t.kind == TypeInfo::Kind::Pointer) return load(s, v);
  return v;
}

Class classOf(const Scope& s, const Value& rv) {
  if (rv.anyType) return Class::Any;
  if (rv.inMemory) return Class::Aggregate;
  if (rv.type < 0) return Class::Pointer;
  return arithOf(s.image(), rv.type) ? Class::Arithmetic : Class::Aggregate;
}

Arith arithOfValue(const Scope& s, const Value& rv) { return *arithOf(s.image(), rv.type); }

std::string category(const Scope& s, const Value& rv) {
  switch (classOf(s, rv)) {
    case Class::Pointer:
      return "pointer";
    case Class::Arithmetic:
      return typeOf(s.image(), rv.type).name;
    case Class::Any:
      return "?";
    case Class::Aggregate:
      break;
  }
  const TypeInfo& t = typeOf(s.image(), rv.type);
  if (t.kind == TypeInfo::Kind::Struct) return "struct";
  if (t.kind == TypeInfo::Kind::Union) return "union";
  return t.name;
}

}  // namespace simbot::inspect
