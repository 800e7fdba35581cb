// Reading a stopped robot's variables by their C names: the expressions
// the debugger's print, display, watch and break ... if take, and --watch.
//
//   expr    := or
//   or      := and ("||" and)*          and := cmp ("&&" cmp)*
//   cmp     := sum (("=="|"!="|"<"|"<="|">"|">=") sum)?
//   sum     := term (("+"|"-") term)*    term := unary (("*"|"/"|"%") unary)*
//   unary   := ("-"|"!"|"*"|"&") unary | slice
//   slice   := postfix ("@" unary)?      an array of that many elements
//   postfix := primary ("[" expr "]" | "." NAME | "->" NAME)*
//   primary := NAME | FUNCTION "::" NAME | NUMBER | "'" CHAR "'" | "(" expr ")"
//
// A NAME is looked up as C would from the selected frame: its function's
// autos and parameters in scope at its line (innermost block first), its
// statics, then the globals. FUNCTION::NAME is a static of that function,
// or an auto of its innermost activation on the stack. Values are read from
// the VM's memory with the compiler's types (vm::TypeInfo): Dynamic C's
// char unsigned, int 16 bits, long 32, float IEEE single, pointers 16.
#pragma once
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "vm/image.h"
#include "vm/vm.h"

namespace simbot::inspect {

// A bad expression, or one that names nothing here: one line for the user.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Where names are looked up: a VM and one of its activations
// (Vm::activations(), 0 = innermost).
struct Scope {
  const vm::Vm& vm;
  std::vector<vm::Vm::Activation> activations;
  int frame = 0;
  explicit Scope(const vm::Vm& v, int selected = 0);
  const vm::Image& image() const { return vm.image(); }
  const vm::Symbol* function() const;  // the selected frame's
  int line() const;                    // the selected frame's current line
};

// A value: an object in robot memory (an lvalue of a type in the image's
// table, `count` > 0 for an `@` slice) or a number the expression made.
struct Value {
  int32_t type = -1;  // vm::Image::types; -1: a number
  bool inMemory = false;
  uint16_t address = 0;
  int count = 0;         // a slice: this many elements of `type` from address
  int frame = -1;        // an auto: the activation (Scope::activations) holding it
  int32_t pointee = -1;  // a number that is an address (&x, p + 1): the type there
  bool isFloat = false;
  int64_t integer = 0;
  double real = 0;
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
  struct Node;

 private:
  std::string text_;
  std::unique_ptr<Node> root_;
};

// Whether every name the expression reads is a variable somewhere in the
// image (a global, or a static, auto or parameter of some function; for
// FUNCTION::NAME, of that function), whatever is in scope now.
bool namesExist(const vm::Image& image, const Expression& expression);

// The value as the debugger prints it: numbers in decimal (chars with
// their character, pointers in hex, a char pointer with its string),
// char arrays as a string and their bytes, arrays in braces, structs with
// their members' names.
std::string format(const Scope& scope, const Value& value);
// The C type of a value: "char[9]", "struct pt", "int" ("long" for a number).
std::string typeName(const Scope& scope, const Value& value);
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
