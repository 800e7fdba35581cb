// inspect/format.cpp -- values as the debugger prints them: naturally (by
// their type), with gdb's format letters (print/x), as memory (x/NFU),
// and their types (whatis, ptype); and values taken apart for DAP's views.
#include <fmt/format.h>

#include <bit>

#include "inspect/inspect.h"
#include "inspect/tree.h"
#include "inspect/types.h"

namespace simbot::inspect {

using vm::Symbol;
using vm::TypeInfo;

namespace {

constexpr int kMaxShownElements = 200;  // longer arrays end in "..."
constexpr int kMaxStringChars = 80;     // a char pointer's string
constexpr int kMaxExamineString = 200;  // x/s: one string's characters
constexpr int kMaxExamineUnits = 4096;  // x/N: N at most

bool isCharType(const TypeInfo& t) {
  return t.kind == TypeInfo::Kind::Scalar &&
         (t.scalar == Symbol::Value::Char || t.scalar == Symbol::Value::SChar);
}

std::string charText(int64_t c) {
  if (c == '\'' || c == '\\') return fmt::format("'\\{}'", static_cast<char>(c));
  if (c >= 0x20 && c < 0x7F) return fmt::format("'{}'", static_cast<char>(c));
  if (c == 0) return "'\\0'";
  return fmt::format("'\\x{:02x}'", static_cast<uint8_t>(c));
}

std::string quoted(const Scope& s, uint16_t a, int limit, bool& ended) {
  std::string out = "\"";
  ended = false;
  for (int k = 0; k < limit; ++k) {
    const uint8_t c = s.vm->read8(static_cast<uint16_t>(a + k));
    if (c == 0) {
      ended = true;
      break;
    }
    if (c == '"' || c == '\\')
      out += fmt::format("\\{}", static_cast<char>(c));
    else if (c >= 0x20 && c < 0x7F)
      out += static_cast<char>(c);
    else
      out += fmt::format("\\x{:02x}", c);
  }
  return out + "\"";
}

// The data symbol (a global or a static) whose memory holds an address:
// "<buf>", "<bot+4>"; empty for none.
std::string label(const Scope& s, uint32_t address) {
  for (const Symbol& sym : s.image().symbols) {
    if ((sym.kind != Symbol::Kind::Global && sym.kind != Symbol::Kind::Static) || sym.size == 0)
      continue;
    if (address >= sym.address && address < sym.address + sym.size)
      return address == sym.address ? fmt::format("<{}>", sym.name)
                                    : fmt::format("<{}+{}>", sym.name, address - sym.address);
  }
  return "";
}

// A pointer's value: its address, then a function's name or a string.
std::string pointerText(const Scope& s, int32_t pointee, int64_t address) {
  std::string out = fmt::format("0x{:04X}", address);
  if (pointee < 0) return out;
  const TypeInfo& pt = typeOf(s.image(), pointee);
  if (pt.kind == TypeInfo::Kind::Function) {
    if (const Symbol* fn = s.image().functionAt(static_cast<uint32_t>(address));
        fn && fn->address == static_cast<uint32_t>(address))
      out += fmt::format(" <{}>", fn->name);
  } else if (isCharType(pt) && address >= vm::kNullPageEnd) {
    bool ended = false;
    out += " " + quoted(s, static_cast<uint16_t>(address), kMaxStringChars, ended);
    if (!ended) out += "...";
  }
  return out;
}

// A number (an rvalue) by its type.
std::string numberText(const Scope& s, const Value& v) {
  if (v.type < 0) return pointerText(s, v.pointee, v.integer);
  const TypeInfo& t = typeOf(s.image(), v.type);
  if (arithOf(s.image(), v.type) == Arith::Float) return fmt::format("{}", v.real);
  if (isCharType(t)) return fmt::format("{} {}", v.integer, charText(v.integer));
  return fmt::format("{}", v.integer);
}

// A number's bits at its own width, with a format letter. `pad`: to the
// width, as x's command shows hex and binary.
std::string letterText(const Scope& s, const Value& v, char letter, bool pad) {
  int width = 2;  // an address's
  uint64_t bits = static_cast<uint64_t>(v.integer) & 0xFFFF;
  if (v.type >= 0) {
    const Arith a = arithOfValue(s, v);
    width = compiler::arithSize(a);
    bits = a == Arith::Float
               ? std::bit_cast<uint32_t>(v.real)
               : static_cast<uint64_t>(v.integer) & ((uint64_t{1} << (width * 8)) - 1);
  }
  const uint64_t sign = uint64_t{1} << (width * 8 - 1);
  switch (letter) {
    case 'x':
      return pad ? fmt::format("0x{:0{}x}", bits, width * 2) : fmt::format("0x{:x}", bits);
    case 'z':
      return fmt::format("0x{:0{}x}", bits, width * 2);
    case 'o':
      return bits ? fmt::format("0{:o}", bits) : "0";
    case 't':
      return pad ? fmt::format("{:0{}b}", bits, width * 8) : fmt::format("{:b}", bits);
    case 'd':
      return fmt::format("{}", static_cast<int64_t>(bits & sign ? bits - (sign << 1) : bits));
    case 'u':
      return fmt::format("{}", bits);
    case 'c':
      return fmt::format("{} {}", bits & 0xFF, charText(static_cast<int64_t>(bits & 0xFF)));
    case 'a': {
      const std::string where = label(s, static_cast<uint32_t>(bits));
      return fmt::format("0x{:04X}{}", bits, where.empty() ? "" : " " + where);
    }
    default:
      return numberText(s, v);
  }
}

std::string objectText(const Scope& s, int32_t type, uint16_t a, int count, char letter);

std::string elementsText(const Scope& s, int32_t element, uint16_t a, int count, char letter) {
  const TypeInfo& e = typeOf(s.image(), element);
  std::string out;
  if (isCharType(e) && !letter) {
    // A char array: its string (to the first NUL inside it) and every byte.
    bool ended = false;
    out = quoted(s, a, count, ended);
    if (!ended) out += " (no NUL)";
    out += " {";
    for (int k = 0; k < count && k < kMaxShownElements; ++k)
      out += fmt::format("{}0x{:02X}", k ? " " : "", s.vm->read8(static_cast<uint16_t>(a + k)));
    return out + (count > kMaxShownElements ? " ...}" : "}");
  }
  out = "{";
  for (int k = 0; k < count && k < kMaxShownElements; ++k)
    out +=
        (k ? ", " : "") + objectText(s, element, static_cast<uint16_t>(a + k * e.size), 0, letter);
  return out + (count > kMaxShownElements ? ", ...}" : "}");
}

std::string objectText(const Scope& s, int32_t type, uint16_t a, int count, char letter) {
  if (count > 0) return elementsText(s, type, a, count, letter);
  const TypeInfo& t = typeOf(s.image(), type);
  switch (t.kind) {
    case TypeInfo::Kind::Scalar:
    case TypeInfo::Kind::Pointer: {
      Value object;
      object.type = type;
      object.inMemory = true;
      object.address = a;
      return letterText(s, load(s, object), letter, false);
    }
    case TypeInfo::Kind::Array:
      if (t.count == 0) return fmt::format("0x{:04X} (an array of unknown length)", a);
      return elementsText(s, t.base, a, t.count, letter);
    case TypeInfo::Kind::Struct:
    case TypeInfo::Kind::Union: {
      std::string out = "{";
      for (size_t k = 0; k < t.fields.size(); ++k)
        out += fmt::format("{}{} = {}", k ? ", " : "", t.fields[k].name,
                           objectText(s, t.fields[k].type,
                                      static_cast<uint16_t>(a + t.fields[k].offset), 0, letter));
      return out + "}";
    }
    default:
      return "(" + t.name + ")";
  }
}

// A member's declaration as C spells it: "char name[6]", "int (*fp)()".
std::string declaration(const std::string& type, const std::string& name) {
  if (const auto star = type.find("(*)"); star != std::string::npos)
    return type.substr(0, star + 2) + name + type.substr(star + 2);
  if (const auto bracket = type.find('['); bracket != std::string::npos)
    return type.substr(0, bracket) + " " + name + type.substr(bracket);
  return type + (type.back() == '*' ? "" : " ") + name;
}

}  // namespace

Format parseFormat(const std::string& spec, bool examine) {
  Format f;
  size_t i = 0;
  if (i < spec.size() && spec[i] == '/') ++i;
  auto bad = [&](const std::string& why) {
    throw Error(fmt::format("'/{}': {}", spec.substr(spec[0] == '/' ? 1 : 0), why));
  };
  if (examine) {
    int64_t count = 0;
    bool digits = false;
    for (; i < spec.size() && spec[i] >= '0' && spec[i] <= '9'; ++i) {
      digits = true;
      count = std::min<int64_t>(count * 10 + (spec[i] - '0'), kMaxExamineUnits + 1);
    }
    if (digits && count == 0) bad("a count of 0 units");
    if (count > kMaxExamineUnits) bad(fmt::format("at most {} units", kMaxExamineUnits));
    if (digits) f.count = static_cast<int>(count);
  }
  for (; i < spec.size(); ++i) {
    const char c = spec[i];
    if (std::string_view("xduotcaz").find(c) != std::string_view::npos || (examine && c == 's')) {
      if (f.letter) bad("two format letters");
      f.letter = c;
    } else if (examine && (c == 'b' || c == 'h' || c == 'w')) {
      if (f.unit) bad("two unit letters");
      f.unit = c == 'b' ? 1 : c == 'h' ? 2 : 4;
    } else if (examine && c == 'g') {
      bad("the robot has no 8-byte units (b, h or w)");
    } else {
      bad(examine ? "a format letter is one of x d u o t c a z s, a unit b h w"
                  : "a format letter is one of x d u o t c a z");
    }
  }
  if (!examine && !f.letter) bad("no format letter");
  return f;
}

std::string format(const Scope& scope, const Value& value, const Format& how) {
  if (!scope.vm) throw Error("the robot has no state to read");
  if (value.anyType || !value.known) throw Error("a value that is not known");
  if (value.inMemory) return objectText(scope, value.type, value.address, value.count, how.letter);
  return letterText(scope, value, how.letter, false);
}

std::string examine(const Scope& scope, const Value& at, const Format& how) {
  if (!scope.vm) throw Error("the robot has no state to read");
  const Value v = rvalue(scope, at);
  const Class c = classOf(scope, v);
  if (!v.known || c == Class::Any) throw Error("an address that is not known");
  if (c == Class::Aggregate || (c == Class::Arithmetic && arithOfValue(scope, v) == Arith::Float))
    throw Error(fmt::format("x needs an address, not a {}", category(scope, v)));
  if (v.integer < 0 || v.integer > 0xFFFF)
    throw Error(fmt::format("address {} is outside the robot's 64 KiB", v.integer));
  const char letter = how.letter ? how.letter : 'x';
  const int unit = how.unit                           ? how.unit
                   : letter == 'a'                    ? 2
                   : (letter == 'c' || letter == 's') ? 1
                                                      : 4;
  uint32_t a = static_cast<uint32_t>(v.integer);
  std::string out;
  if (letter == 's') {
    for (int k = 0; k < how.count && a <= 0xFFFF; ++k) {
      const uint32_t room = std::min<uint32_t>(kMaxExamineString, 0x10000 - a);
      uint32_t n = 0;
      while (n < room && scope.vm->read8(static_cast<uint16_t>(a + n)) != 0) ++n;
      bool ended = false;
      const std::string text = quoted(scope, static_cast<uint16_t>(a), static_cast<int>(n), ended);
      const std::string where = label(scope, a);
      out += fmt::format("0x{:04X}{}:\t{}{}\n", a, where.empty() ? "" : " " + where, text,
                         n < room ? "" : "...");
      a += n + (n < room ? 1 : 0);  // on past its NUL
    }
    return out;
  }
  const uint64_t bytes = static_cast<uint64_t>(how.count) * static_cast<uint64_t>(unit);
  if (a + bytes > 0x10000)
    throw Error(fmt::format("x/{}{}{} from 0x{:04X} would read past 0xFFFF", how.count, letter,
                            unit == 1   ? 'b'
                            : unit == 2 ? 'h'
                                        : 'w',
                            a));
  const int perLine = unit == 4 || letter == 'a' ? 4 : 8;
  const Arith asType = unit == 1 ? Arith::Char : unit == 2 ? Arith::UInt : Arith::ULong;
  for (int k = 0; k < how.count; ++k, a += static_cast<uint32_t>(unit)) {
    if (k % perLine == 0) {
      if (k) out += "\n";
      const std::string where = label(scope, a);
      out += fmt::format("0x{:04X}{}:", a, where.empty() ? "" : " " + where);
    }
    const auto at16 = static_cast<uint16_t>(a);
    const int64_t word = unit == 1   ? scope.vm->read8(at16)
                         : unit == 2 ? scope.vm->read16(at16)
                                     : scope.vm->read32(at16);
    out += "\t" + letterText(scope, integerValue(scope.image(), asType, word), letter, true);
  }
  return out + "\n";
}

std::string typeName(const Scope& scope, const Value& value) {
  if (value.anyType) return "?";
  if (!value.inMemory && value.type < 0) return pointerName(scope.image(), value.pointee);
  const std::string& name = typeOf(scope.image(), value.type).name;
  return value.count > 0 ? fmt::format("{}[{}]", name, value.count) : name;
}

std::string describeType(const Scope& scope, const std::string& text, bool expand) {
  int32_t type = -1;
  std::string name;
  if (const std::optional<TypeName> t = parseTypeName(text)) {
    const Resolved r = resolve(scope.image(), *t);
    if (r.pointee >= 0) return pointerName(scope.image(), r.pointee);
    type = r.type;
    name = typeOf(scope.image(), type).name;
  } else {
    const Value v = Expression(text).evaluate(scope);
    name = typeName(scope, v);
    if (v.count == 0 && (v.inMemory || v.type >= 0)) type = v.type;
  }
  if (!expand || type < 0) return name;
  const TypeInfo& t = typeOf(scope.image(), type);
  if (t.kind != TypeInfo::Kind::Struct && t.kind != TypeInfo::Kind::Union) return name;
  std::string out = name + " {\n";
  for (const TypeInfo::Field& f : t.fields)
    out += "    " + declaration(typeOf(scope.image(), f.type).name, f.name) + ";\n";
  return out + "}";
}

std::vector<uint8_t> bytes(const Scope& scope, const Value& value) {
  std::vector<uint8_t> out;
  if (!value.inMemory || !scope.vm) return out;
  const uint32_t size =
      value.count > 0 ? typeOf(scope.image(), value.type).size * static_cast<uint32_t>(value.count)
                      : typeOf(scope.image(), value.type).size;
  out.reserve(size);
  for (uint32_t k = 0; k < size; ++k)
    out.push_back(scope.vm->read8(static_cast<uint16_t>(value.address + k)));
  return out;
}

std::vector<Child> children(const Scope& scope, const Value& value) {
  std::vector<Child> out;
  if (!value.inMemory) return out;
  const TypeInfo& t = typeOf(scope.image(), value.type);
  auto elementsFrom = [&](int32_t element, uint16_t a, int count) {
    const uint32_t size = typeOf(scope.image(), element).size;
    for (int k = 0; k < count && k < kMaxShownElements; ++k) {
      Value v;
      v.type = element;
      v.inMemory = true;
      v.address = static_cast<uint16_t>(a + k * size);
      out.push_back({fmt::format("[{}]", k), v});
    }
  };
  if (value.count > 0) {
    elementsFrom(value.type, value.address, value.count);
  } else if (t.kind == TypeInfo::Kind::Array) {
    elementsFrom(t.base, value.address, t.count);
  } else if (t.kind == TypeInfo::Kind::Struct || t.kind == TypeInfo::Kind::Union) {
    for (const TypeInfo::Field& f : t.fields) {
      Value v;
      v.type = f.type;
      v.inMemory = true;
      v.address = static_cast<uint16_t>(value.address + f.offset);
      out.push_back({"." + f.name, v});
    }
  } else if (t.kind == TypeInfo::Kind::Pointer && t.base >= 0 && scope.vm) {
    const TypeInfo& target = typeOf(scope.image(), t.base);
    const uint16_t p = scope.vm->read16(value.address);
    if (p >= vm::kNullPageEnd && target.kind != TypeInfo::Kind::Void &&
        target.kind != TypeInfo::Kind::Function) {
      Value v;
      v.type = t.base;
      v.inMemory = true;
      v.address = p;
      out.push_back({"*", v});
    }
  }
  return out;
}

bool hasChildren(const Scope& scope, const Value& value) {
  if (!value.inMemory) return false;
  if (value.count > 0) return true;
  const TypeInfo& t = typeOf(scope.image(), value.type);
  if (t.kind == TypeInfo::Kind::Array || t.kind == TypeInfo::Kind::Struct ||
      t.kind == TypeInfo::Kind::Union)
    return true;
  if (t.kind == TypeInfo::Kind::Pointer && t.base >= 0) {
    const TypeInfo& target = typeOf(scope.image(), t.base);
    return target.kind != TypeInfo::Kind::Void && target.kind != TypeInfo::Kind::Function;
  }
  return false;
}

}  // namespace simbot::inspect
