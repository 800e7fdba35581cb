// Reading a stopped robot's variables by their C names: the expressions
// the debugger's print, display, watch, break ... if and x take, DAP's
// evaluate, and --watch. They are C expressions computed as the robot's
// code would compute them (Dynamic C on the Z180: char 8-bit unsigned,
// int 16-bit, wrapping, long 32, float IEEE single, pointers 16; C89's
// promotions and usual conversions, compiler/arith.h), with gdb's a@n.
//
//   expr       := cond
//   cond       := logor ("?" expr ":" cond)?
//   logor      := logand ("||" logand)*
//   logand     := bitor ("&&" bitor)*
//   bitor      := bitxor ("|" bitxor)*
//   bitxor     := bitand ("^" bitand)*
//   bitand     := equality ("&" equality)*
//   equality   := relational (("==" | "!=") relational)*
//   relational := shift (("<" | "<=" | ">" | ">=") shift)*
//   shift      := slice (("<<" | ">>") slice)*
//   slice      := additive ("@" additive)*       n elements from an lvalue
//   additive   := term (("+" | "-") term)*
//   term       := cast (("*" | "/" | "%") cast)*
//   cast       := "(" type-name ")" cast | unary
//   unary      := ("+" | "-" | "!" | "~" | "*" | "&") cast
//               | "sizeof" "(" type-name ")" | "sizeof" unary | postfix
//   postfix    := primary ("[" expr "]" | "." NAME | "->" NAME)*
//   primary    := NAME | FUNCTION "::" NAME | NUMBER | CHAR | "(" expr ")"
//   type-name  := (TYPE-WORD+ | ("struct" | "union") TAG) "*"*
//
// A NAME is looked up as C would from the selected frame: its function's
// autos and parameters in scope at its line (innermost block first), its
// statics, then the globals. FUNCTION::NAME is a static of that function,
// or an auto of its innermost activation on the stack. Values are read
// from the VM's memory with the compiler's types (vm::TypeInfo). Constants
// take Dynamic C's types (32767 an int, 32768 a long, 0xFFFF an unsigned
// int); one past 0xFFFFFFFF is an error. Shifts run as the Z180 code's
// loop does (by the count's low byte: 16 or more leave 0, or the sign); a
// division by zero is an error, as it is a fault on the robot.
#pragma once
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "vm/image.h"
#include "vm/vm.h"

namespace simbot::inspect {

struct Node;  // tree.h

// A bad expression, or one that names nothing here: one line for the user.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Where names are looked up: a VM and one of its activations
// (Vm::activations(), 0 = innermost); or, without a VM, only an image (a
// --watch checked before the run: names have no values there).
struct Scope {
  const vm::Vm* vm = nullptr;
  std::vector<vm::Vm::Activation> activations;
  int frame = 0;
  explicit Scope(const vm::Vm& v, int selected = 0);
  explicit Scope(const vm::Image& image);
  const vm::Image& image() const { return *image_; }
  const vm::Symbol* function() const;  // the selected frame's
  int line() const;                    // the selected frame's current line

 private:
  const vm::Image* image_;
};

// A value: an object in robot memory (an lvalue of a type in the image's
// table, `count` > 0 for an `@` slice) or a number the expression made,
// with its C type (a scalar type's index, or an address of `pointee`).
struct Value {
  int32_t type = -1;  // types.h: the image's table, then the basic types; -1: an address
  bool inMemory = false;
  uint16_t address = 0;
  int count = 0;         // a slice: this many elements of `type` from address
  int frame = -1;        // an auto: the activation (Scope::activations) holding it
  int32_t pointee = -1;  // an address (&x, p + 1): the type there
  int64_t integer = 0;   // an integer or address, as its type holds it
  float real = 0;        // a float
  // Evaluation only: the type is known but not the value (the operand of
  // sizeof, the arm of ?: not taken, memory without a VM); anyType: not
  // even the type (a name in a check without a frame).
  bool known = true;
  bool anyType = false;
};

class Expression {
 public:
  // Throws Error at the first token that does not fit the grammar.
  explicit Expression(const std::string& text);
  ~Expression();
  Expression(Expression&&) noexcept;
  Expression& operator=(Expression&&) noexcept;
  const std::string& text() const { return text_; }
  Value evaluate(const Scope& scope) const;  // throws Error
  // The names the expression reads: (FUNCTION or "", NAME).
  std::vector<std::pair<std::string, std::string>> names() const;
  const Node& root() const { return *root_; }

 private:
  std::string text_;
  std::unique_ptr<Node> root_;
};

// Whether every name the expression reads is a variable somewhere in the
// image (a global, or a static, auto or parameter of some function; for
// FUNCTION::NAME, of that function), whatever is in scope now.
bool namesExist(const vm::Image& image, const Expression& expression);
// Throws Error if the expression can never be evaluated in this image,
// whatever the robot's state (1/0, x % 0, buf[0]@0, (struct nosuch *) p);
// what depends on the names' values is left to each evaluation.
void check(const vm::Image& image, const Expression& expression);

// gdb's output formats: print/x, display/x, x/4xb. A letter shows a
// number's bits at its own width (an int -1 /x is 0xffff; a float's IEEE
// bits); aggregates show each member so.
struct Format {
  char letter = 0;  // 0 (as its type), x d u o t c a z; x's command also s
  int count = 1;    // x: how many units
  int unit = 0;     // x: bytes per unit (b 1, h 2, w 4); 0: the letter's default
};
// "/x", "/4xb": what follows a command word; Error for what gdb would
// refuse or this target lacks (a unit g, a count of 0).
Format parseFormat(const std::string& spec, bool examine);

// The value as the debugger prints it: numbers in decimal (chars with
// their character, pointers in hex, a char pointer with its string),
// char arrays as a string and their bytes, arrays in braces, structs with
// their members' names; with a format letter, gdb's /x and the others.
std::string format(const Scope& scope, const Value& value, const Format& how = {});
// x/NFU: `how.count` units of memory from the address `at` gives (a
// pointer, an array, or an integer 0..0xFFFF), in lines as gdb prints them.
std::string examine(const Scope& scope, const Value& at, const Format& how);
// The C type of a value: "char[9]", "struct pt", "int", "unsigned long".
std::string typeName(const Scope& scope, const Value& value);
// whatis / ptype of a type name or an expression: its type's name;
// `expand` spells out a struct's or union's members as ptype does.
std::string describeType(const Scope& scope, const std::string& text, bool expand);
// Numbers: the value as an integer or a real (a condition's truth, a
// --watch's scalar); false for aggregates.
bool scalar(const Scope& scope, const Value& value, int64_t& integer, double& real, bool& isFloat);
bool truth(const Scope& scope, const Value& value);
// The raw bytes of an object (a watchpoint compares them), empty for a number.
std::vector<uint8_t> bytes(const Scope& scope, const Value& value);

// The members of an aggregate (struct members, array elements, a slice's
// elements, a pointer's target), each with its name as an expression
// suffix ("[3]", ".x", "*"), for structured views (DAP variables).
struct Child {
  std::string name;
  Value value;
};
std::vector<Child> children(const Scope& scope, const Value& value);
bool hasChildren(const Scope& scope, const Value& value);

// Every data symbol visible from the selected frame: its autos and
// parameters in scope, its statics, then the globals (DAP scopes).
struct Variable {
  std::string name;
  Value value;
};
std::vector<Variable> locals(const Scope& scope);
std::vector<Variable> globals(const Scope& scope);

}  // namespace simbot::inspect
