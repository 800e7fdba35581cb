// Types, objects and the syntax tree (internal), shared by the parser, which
// builds and type-checks them, and the code generator, which walks them.
//
// Everything lives in the Program's arenas (deques, so pointers stay valid)
// and is referred to by plain pointers, as in chibicc. Every expression node
// carries its C type after the usual conversions: the parser inserts explicit
// Cast nodes for implicit conversions and folds constant subtrees, so the
// code generator never has to reason about C's typing rules.
#pragma once
#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "compiler/compiler.h"
#include "compiler/diagnostics.h"
#include "compiler/preprocess.h"

namespace simbot::compiler {

// ---- types ----

enum class TypeKind : uint8_t {
  Void,
  Char,   // plain and unsigned char: 8-bit unsigned, as in Dynamic C
  SChar,  // signed char: 8-bit two's complement
  Int,
  UInt,
  Long,
  ULong,
  Float,
  Ptr,
  Array,
  Func,
  Struct,
  Union
};

struct Type;

struct Member {
  std::string name;
  Type* type = nullptr;
  int offset = 0;
};

struct Param {
  std::string name;
  Type* type = nullptr;
  Pos pos;
  bool isRegister = false;
};

struct Type {
  TypeKind kind = TypeKind::Int;
  int size = 0;          // bytes (an array of unknown length: 0)
  Type* base = nullptr;  // pointee, element or return type
  int arrayLen = 0;      // -1: unknown, "[]"
  int depth = 0;         // derivation depth, capped by the parser
  // struct / union
  std::string tag;
  std::vector<Member> members;
  bool complete = true;
  // function
  std::vector<Param> params;
  bool hasProto = false;  // parameter types known
  bool krNames = false;   // K&R identifier list: types come after ")"
  // "..." after the parameters: accepted in declarations of the library's
  // variadic routines only (printf); ellipsisPos says where, for the error.
  bool variadic = false;
  Pos ellipsisPos;
};

// The basic types are shared immutable singletons.
Type* tyVoid();
Type* tyChar();
Type* tySChar();
Type* tyInt();
Type* tyUInt();
Type* tyLong();
Type* tyULong();
Type* tyFloat();

bool isInteger(const Type* t);  // char, int, unsigned, long, unsigned long
bool isArith(const Type* t);    // integer or float
bool isPtrLike(const Type* t);  // pointer or array
bool isScalar(const Type* t);   // arithmetic or pointer-like
bool isStructLike(const Type* t);
bool isUnsigned(const Type* t);  // char, unsigned, unsigned long, pointers
bool sameType(const Type* a, const Type* b);

// How a value travels in an eval-stack slot.
enum class Slot : uint8_t { Byte, Word, Long, Float, Struct, None };
Slot slotOf(const Type* t);           // B (char), W (int/unsigned/ptr/array), L, F
std::string slotName(const Type* t);  // "16-bit", "32-bit", "float" (for messages)

std::string typeName(const Type* t);      // "unsigned long", "char[9]", "int *"
std::string typeCategory(const Type* t);  // "pointer", "struct", or typeName

// ---- objects ----

enum class Storage : uint8_t { Global, Static, Auto, Function };

struct Function;
struct Init;
struct Node;

struct Obj {
  std::string name;     // as declared
  std::string symName;  // "function.name" for locals and parameters
  Type* type = nullptr;
  Pos pos;
  Storage storage = Storage::Global;
  bool isParam = false;
  bool isRegister = false;
  bool isExtern = false;
  Init* init = nullptr;    // Global/Static: initial value (Image::data)
  Function* fn = nullptr;  // Storage::Function
  int address = -1;        // data address, or frame offset for autos
  bool biosTimer = false;  // TICK_TIMER, MS_TIMER, SEC_TIMER (the BIOS's)
  int scopeEnd = 0;        // autos and parameters: their block's last line
};

struct Function {
  Obj* obj = nullptr;
  std::string name;
  Type* type = nullptr;  // TypeKind::Func
  std::vector<Obj*> params;
  std::vector<Obj*> locals;  // declaration order, statics and autos
  Node* body = nullptr;
  bool defined = false;
  bool implicit = false;   // only known from a call (implicit "int f()")
  bool isHandler = false;  // interrupt function
  bool debug = true;       // DBG before each statement
  Pos defPos;
  bool called = false;
  Pos firstCall;
  bool addressTaken = false;  // named as a value (a function pointer's)
  Pos addressPos;
  std::vector<Node*> uncheckedCalls;  // calls made before the parameters were known
  // code generation
  int address = -1;
  int codeSize = 0;
  int frameSize = 0;
};

// An initialiser: a scalar expression, a string for a char array, or the
// elements of an array or the members of a struct (missing ones are zero).
struct Init {
  Type* type = nullptr;
  Node* expr = nullptr;
  std::vector<Init*> children;
};

// ---- syntax tree ----

enum class NodeKind : uint8_t {
  // expressions
  Num,
  FNum,
  Str,
  Var,
  Add,
  Sub,
  Mul,
  Div,
  Mod,
  BitAnd,
  BitOr,
  BitXor,
  Shl,
  Shr,
  Eq,
  Ne,
  Lt,
  Le,
  Gt,
  Ge,
  LogAnd,
  LogOr,
  Not,
  BitNot,
  Neg,
  Assign,
  OpAssign,
  IncDec,
  Cond,
  Comma,
  Cast,
  Deref,
  Addr,
  Member,
  Call,     // callee: a direct call; else lhs: the function pointer called through
  FuncRef,  // callee: a function designator, its value the function's address
  LibCall,
  Intrinsic,
  // statements
  Block,
  ExprStmt,
  If,
  While,
  DoWhile,
  For,
  Switch,
  Case,
  Break,
  Continue,
  Return,
  Goto,
  Label,
  Empty,
  DeclInit,
  // costatements (Dynamic C)
  Costate,  // var: its CoData; then: body; ival: 1 if always_on
  Waitfor,  // cond: the expression; costate: the enclosing Costate
  Yield,    // costate: the enclosing Costate
  Abort,    // costate: the enclosing Costate
};

struct Node {
  NodeKind kind = NodeKind::Empty;
  Type* type = nullptr;  // expressions: the C type of the value
  Pos pos;
  int depth = 1;  // tree height, capped by the parser
  Pos endPos;     // Block: its closing brace

  Node* lhs = nullptr;
  Node* rhs = nullptr;
  Node* cond = nullptr;  // If/While/DoWhile/For/Cond
  Node* then = nullptr;  // If/loops: body; Case/Label: the labelled statement
  Node* els = nullptr;
  Node* init = nullptr;     // For
  Node* inc = nullptr;      // For
  std::vector<Node*> list;  // Block statements, call arguments
  std::vector<Pos> argPos;  // call arguments' positions

  Obj* var = nullptr;           // Var, DeclInit
  Init* initv = nullptr;        // DeclInit
  int64_t ival = 0;             // Num value (already wrapped to its type), Case value
  float fval = 0;               // FNum
  std::string str;              // Str bytes (no NUL), label names
  int offset = 0;               // Member
  NodeKind op = NodeKind::Add;  // OpAssign: the arithmetic
  Type* opType = nullptr;       // OpAssign: type the arithmetic is done in
  bool prefix = false;          // IncDec
  bool parenthesized = false;   // written inside "( )" (no parentheses warning)
  int delta = 1;                // IncDec: +1 or -1
  Function* callee = nullptr;   // Call (direct), FuncRef
  int lib = 0;                  // LibCall: builtin id; Intrinsic: 0 EI, 1 DI
  bool isDefault = false;       // Case
  std::vector<Node*> cases;     // Switch: its case and default labels
  Node* costate = nullptr;      // Waitfor/Yield/Abort: the enclosing Costate
  int label = -1;               // code generation
};

struct IntVecBinding {
  int vector = 0;
  Function* handler = nullptr;
  Pos pos;
};

struct Program {
  std::deque<Type> types;
  std::deque<Node> nodes;
  std::deque<Obj> objs;
  std::deque<Function> funcs;
  std::deque<Init> inits;

  std::vector<Obj*> globals;         // definitions, in order of appearance
  std::vector<Function*> functions;  // defined functions, in order
  Function* main = nullptr;
  std::vector<IntVecBinding> vectors;
  // The BIOS timer's counters (TICK_TIMER, MS_TIMER, SEC_TIMER, the
  // millisecond fraction): set, and defined in globals, once the program
  // uses the timer library (a timer variable or a Delay function).
  std::array<Obj*, 4> timer{};
};

// parser.cpp: the whole translation unit, type-checked. Errors and the
// warnings found while parsing go to `diags`; throws StopCompiling when it
// cannot go on.
void parse(Preprocessor& pp, const Options& options, Program& prog, Diagnostics& diags);
// warnings.cpp: the warnings that need whole functions or the whole program
// (unbound-handler, uninitialized, send-without-delay), on an error-free
// Program.
void analyze(const Program& prog, Diagnostics& diags);
// codegen.cpp: the image (code, line table, data, vectors, symbols).
vm::Image generate(Program& prog);

}  // namespace simbot::compiler
