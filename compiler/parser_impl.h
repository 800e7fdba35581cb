// compiler/parser_impl.h -- internal: the parser's class and what its
// parts share. The parser is one class whose rules are split by job:
// parser.cpp (the token cursor, scopes, the run and error recovery),
// parse_decl.cpp (declarations and initialisers), parse_stmt.cpp
// (statements and costatements), parse_expr.cpp (expressions) and
// types.cpp (the type rules that build typed nodes). Nothing outside
// compiler/ includes this header.
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include "compiler/arith.h"
#include "compiler/ast.h"
#include "vm/bytecode.h"
#include "vm/image.h"

namespace simbot::compiler::detail {

inline constexpr int kMaxDepth = 200;       // nested parens, blocks, unary operators, ...
inline constexpr int kMaxTreeDepth = 1000;  // height of an expression tree
inline constexpr int kMaxTypeDepth = 64;    // pointer/array derivations of one type
// Counts a file could make long; each is far beyond what the era's programs
// use (and, for parameters, what fits the expression stack of a call).
inline constexpr size_t kMaxParameters = 64;
inline constexpr size_t kMaxMembers = 512;
inline constexpr int kMaxEnumerators = 4096;

inline const std::unordered_set<std::string_view> kKeywords = {
    "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else", "enum",
    "extern", "float", "for", "goto", "if", "int", "long", "register", "return", "short", "signed",
    "sizeof", "static", "struct", "switch", "typedef", "union", "unsigned", "void", "volatile",
    "while", "interrupt", "reti", "nodebug", "debug", "shared", "protected", "root", "xmem",
    // Dynamic C's costatement words
    "costate", "waitfor", "yield", "abort", "always_on", "init_on", "wfd", "waitfordone"};

inline const std::unordered_set<std::string_view> kDeclWords = {
    "void",   "char",     "short",     "int",   "long",     "float",   "double",
    "signed", "unsigned", "struct",    "union", "enum",     "typedef", "static",
    "extern", "auto",     "register",  "const", "volatile", "shared",  "protected",
    "root",   "xmem",     "interrupt", "reti",  "nodebug",  "debug"};

// Type rules shared by the parser's parts (types.cpp), on compiler/arith.h's.
Arith arithOf(const Type* t);              // an arithmetic type's kind
Type* arithType(Arith a);                  // and back
int64_t wrapTo(int64_t v, const Type* t);  // v as type t holds it
Type* promote(Type* t);                    // char to int
Type* commonType(Type* a, Type* b);        // the usual arithmetic conversions
const char* opSpelling(NodeKind k);        // "+", "<<", ... for messages
// The jump a statement ends with ("return", ...), or null if control can
// fall out of it (parse_stmt.cpp).
const char* endsPath(const Node* n);

inline bool isConst(const Node* n) { return n->kind == NodeKind::Num || n->kind == NodeKind::FNum; }
inline bool truthy(const Node* n) { return n->kind == NodeKind::Num ? n->ival != 0 : n->fval != 0; }

// Thrown inside a function body that lacks its '}' when the next function
// begins: every open block ends and parsing resumes at file level.
struct BackToFileLevel {};

struct VarAttr {
  bool isTypedef = false;
  bool isStatic = false;
  bool isExtern = false;
  bool isAuto = false;
  bool isRegister = false;
  bool isInterrupt = false;
  bool nodebug = false;
  bool debug = false;
  bool sawType = false;
  bool sawStorage = false;
};

struct Declarator {
  Type* type = nullptr;
  std::string name;
  Pos pos;
  bool hasName = false;
};

struct ScopeEntry {
  Obj* var = nullptr;
  Type* typeDef = nullptr;
  bool isConst = false;  // enum constant or predefined name
  int64_t value = 0;
};

struct Scope {
  std::unordered_map<std::string, ScopeEntry> vars;
  std::unordered_map<std::string, Type*> tags;
};

class Parser {
 public:
  Parser(Preprocessor& pp, const Options& options, Program& prog, Diagnostics& diags)
      : pp_(pp), options_(options), prog_(prog), diags_(diags) {}
  void run();

 private:
  // ---- token cursor ----
  const Token& at(size_t idx);
  const Token& cur() { return at(i_); }
  const Token& peek(int k);
  void settle();
  void advance();
  bool is(std::string_view s) { return cur().is(s); }
  bool accept(std::string_view s);
  void expect(std::string_view s);
  void expectSemi(const std::string& what);
  bool isKeyword(const Token& t) const {
    return t.kind == TokKind::Ident && kKeywords.count(t.text);
  }

  struct DepthGuard {
    Parser& p;
    DepthGuard(Parser& parser) : p(parser) {
      // Fatal: recovery would resume inside the very nesting it gave up on.
      if (++p.depth_ > kMaxDepth) p.diags_.fatal(p.cur().pos, "nesting too deep");
    }
    ~DepthGuard() { --p.depth_; }
  };

  // ---- scopes ----
  void enterScope() { scopes_.emplace_back(); }
  // A local's scope ends with the last token read (the block's brace).
  void leaveScope() {
    const int end = i_ > 0 ? at(i_ - 1).pos.line : 0;
    for (auto& [name, entry] : scopes_.back().vars)
      if (entry.var && entry.var->scopeEnd == 0) entry.var->scopeEnd = end;
    scopes_.pop_back();
  }
  ScopeEntry* findVar(const std::string& name);
  Type* findTag(const std::string& name);
  Type* typedefOf(const Token& t);
  bool isDeclStart(const Token& t);

  // ---- arenas ----
  Node* newNode(NodeKind k, Pos pos, Type* ty = nullptr);
  Type* newType(TypeKind k, int size);
  Type* pointerTo(Type* base, Pos pos);
  Type* arrayOf(Type* base, int len, Pos pos);
  Obj* newObj(const std::string& name, Type* ty, Pos pos, Storage st);
  Init* newInit(Type* ty);

  // ---- declarations ----
  void externalDeclaration();
  Type* declspec(VarAttr* attr);
  Type* structDecl(bool isUnion);
  Type* enumSpecifier();
  void declarator(Type* ty, Declarator& d);
  bool startsNestedDeclarator();
  Type* typeSuffix(Type* ty);
  Type* funcParams(Type* ret);
  Type* abstractTypeName();
  void typedefs(Type* base, Declarator& first);
  Function* declareFunction(Declarator& d, const VarAttr& attr);
  void functionDefinition(Declarator& d, const VarAttr& attr);
  void globalVariable(Declarator& d, const VarAttr& attr);
  void localDeclaration(std::vector<Node*>& out);
  Init* initializer(Type*& ty);
  void initializer2(Init* init);
  void arrayInitializer(Init* init, bool braced);
  void structInitializer(Init* init, bool braced);
  bool atInitEnd();
  void checkComplete(Obj* obj);
  void checkCallAgainstDefinition(Function* f, Node* call, bool kinds = true);

  // ---- error recovery ----
  // Where parsing resumes after an error: the token cursor's nesting and the
  // parser's state at the start of the failed statement or declaration.
  struct Resume {
    size_t token = 0;
    int braces = 0, parens = 0;
    size_t scopes = 0, switches = 0;
    int loopDepth = 0, breakDepth = 0;
  };
  Resume resumePoint();
  void recordError(const CompileError& e);
  void skipStatement(const Resume& r);
  void skipExternalDeclaration();
  void poisonSince(size_t token);
  bool libraryDeclaration(const Declarator& d);
  // An error about `t` being incomplete; silent when `t` is a struct or
  // union whose own declaration failed (reported there already).
  [[noreturn]] void incomplete(Pos pos, const Type* t, std::string message);
  bool atFunctionDefinition();
  [[noreturn]] void undeclared(Pos pos, const std::string& name, const std::string& message);

  // ---- warnings ----
  void checkTypeLimits(NodeKind k, const Node* l, const Node* r, Pos pos);

  // ---- statements ----
  Node* statement();
  Node* compoundStatement(bool newScope);
  Node* exprStatement();
  // An expression tested for truth (if, for, while, do-while, waitfor,
  // ?:), and the "(" expr ")" of all but for and ?:. waitfor does not warn
  // about an assignment (parse_stmt.cpp says why).
  Node* condition(Node* e, bool warnAssignment = true);
  Node* parenCondition(bool warnAssignment = true);

  // ---- expressions ----
  Node* expr();
  Node* assign();
  Node* conditional();
  Node* binaryExpr(int minPrecedence);
  Node* cast();
  Node* unary();
  Node* postfix();
  Node* primary();
  Node* funcall(const Token& nameTok, Function* f);
  Node* callThrough(Node* fp, Pos pos);
  Node* funcRef(Function* f, Pos pos);
  void callArguments(Node* n);
  void convertArguments(Node* n, Type* ft, const std::string& to);
  Node* libcall(const Token& nameTok, int lib);
  // The library routine `name` names here, or -1: MATH.LIB's only after
  // #use MATH.LIB.
  int library(const std::string& name) const {
    const int id = vm::libraryIndex(name);
    return id >= 0 && vm::inMathLib(id) && !pp_.uses("math.lib") ? -1 : id;
  }
  int64_t constExpr(Type** type = nullptr);

  // ---- typing helpers ----
  Node* value(Node* e);
  Node* num(int64_t v, Type* ty, Pos pos);
  Node* fnum(double v, Pos pos);
  Node* castTo(Node* e, Type* to, Pos pos);
  Node* binary(NodeKind k, Node* l, Node* r, Pos pos, Type* ty);
  Node* fold(NodeKind k, Node* l, Node* r, Pos pos, Type* ty);
  Node* arith(NodeKind k, Node* l, Node* r, Pos pos);
  Node* newAdd(Node* l, Node* r, Pos pos);
  Node* newSub(Node* l, Node* r, Pos pos);
  Node* ptrOffset(NodeKind k, Node* p, Node* i, Pos pos);
  Node* compare(NodeKind k, Node* l, Node* r, Pos pos);
  Node* logical(NodeKind k, Node* l, Node* r, Pos pos);
  Node* assignConvert(Node* e, Type* ty, Pos pos, const std::string& context);
  Node* newAssign(Node* l, Node* r, Pos pos);
  Node* newOpAssign(NodeKind op, Node* l, Node* r, Pos pos);
  Node* newIncDec(Node* e, int delta, bool prefix, Pos pos);
  Node* newDeref(Node* e, Pos pos);
  Node* newAddr(Node* e, Pos pos);
  Node* member(Node* base, const Token& name, Pos pos);
  bool isLvalue(const Node* n) const;
  [[noreturn]] void badOperands(NodeKind k, Node* l, Node* r, Pos pos);

  void applyPragma(const Token& t);

  // ---- costatements ----
  void predefineCostateNames();
  Node* costateStatement();
  Node* waitforStatement();
  Node* costateControl(NodeKind kind);
  Obj* coDataNamed(const Token& name, int initialState);
  void useTimer();
  [[noreturn]] void notSupported(const Token& t);

  Preprocessor& pp_;
  const Options& options_;
  Program& prog_;
  Diagnostics& diags_;
  std::deque<Token> toks_;
  size_t i_ = 0;
  int braceDepth_ = 0;             // "{" minus "}" the cursor has moved over
  int parenDepth_ = 0;             // "(" minus ")" likewise
  std::vector<bool> braceIsBody_;  // per open "{": a function body's
  bool lastCloseWasBody_ = false;
  // Names met in a declaration that failed: an error about one of them
  // later (undeclared, undefined) follows from that failure, so is silent.
  std::unordered_set<std::string> poisoned_;
  std::unordered_set<std::string> undeclaredHere_;  // reported in this function
  std::string functionNameAhead_;                   // atFunctionDefinition's find
  Pos prevPos_{1, 1, 0};
  int depth_ = 0;
  std::vector<Scope> scopes_;
  bool classAuto_ = false;
  bool nodebugPragma_ = false;

  // the function being parsed
  Function* fn_ = nullptr;
  int loopDepth_ = 0;
  int breakDepth_ = 0;
  std::vector<Node*> costates_;  // the costatements being parsed, innermost last
  Type* coDataType_ = nullptr;
  std::array<Obj*, 4> timerObjs_{};
  bool timerUsed_ = false;
  std::vector<Node*> switches_;
  std::unordered_map<std::string, Node*> labels_;
  std::vector<Node*> gotos_;
};

}  // namespace simbot::compiler::detail
