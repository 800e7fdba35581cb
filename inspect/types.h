// inspect/types.h -- internal: the types of the debugger's values and
// reading them from robot memory (types.cpp). A value's type indexes the
// image's table (vm::Image::types) or, past its end, the basic types,
// which every expression may name whether the program uses them or not
// (a cast to char in a program without a char). Nothing outside inspect/
// includes this header.
#pragma once
#include <optional>
#include <string>

#include "compiler/arith.h"
#include "inspect/inspect.h"
#include "inspect/tree.h"

namespace simbot::inspect {

// The type at an index: the image's, then void and the arithmetic types.
const vm::TypeInfo& typeOf(const vm::Image& image, int32_t type);
int32_t voidType(const vm::Image& image);
int32_t basicType(const vm::Image& image, Arith a);
// An arithmetic type's kind (none for pointers, aggregates and the rest).
std::optional<Arith> arithOf(const vm::Image& image, int32_t type);
// Whether a and b are the same C type (the image's int and the basic int are).
bool sameType(const vm::Image& image, int32_t a, int32_t b);
// A pointer type to `target` in the image's table, or -1: the image has
// none (a pointer value needs only its target; a pointer object's type
// must be in the table).
int32_t pointerTypeTo(const vm::Image& image, int32_t target);
// C's spelling of a pointer to `target`: "int *", "char (*)[9]", "int (*)()".
std::string pointerName(const vm::Image& image, int32_t target);
// The type a type name names (its target, for a pointer: see
// Resolved); Error if it names a struct the program lacks.
struct Resolved {
  int32_t type = -1;     // not a pointer: the type
  int32_t pointee = -1;  // a pointer: what it points at
};
Resolved resolve(const vm::Image& image, const TypeName& name);

// Values that are numbers.
Value integerValue(const vm::Image& image, Arith a, int64_t v);  // v wrapped to a
Value floatValue(const vm::Image& image, float f);
Value addressValue(int32_t pointee, int64_t address);  // wrapped to 16 bits
Value unknownOf(Value v);                              // the same type, no value

// A scalar object's value from memory: integers sign- or zero-extended,
// pointers as addresses of their target; unknown without a VM.
Value load(const Scope& s, const Value& object);

// What an operand is once it is a value (C's "lvalue conversion": an
// array becomes the address of its first element, a scalar object its
// value); aggregates stay objects.
Value rvalue(const Scope& s, const Value& v);
enum class Class : uint8_t { Arithmetic, Pointer, Aggregate, Any };
Class classOf(const Scope& s, const Value& rv);       // of an rvalue
Arith arithOfValue(const Scope& s, const Value& rv);  // Class::Arithmetic only
// C's name of an operand's type for messages: "pointer", "struct", "int".
std::string category(const Scope& s, const Value& rv);

}  // namespace simbot::inspect
