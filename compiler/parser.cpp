// The parser and type checker: preprocessed tokens in, a typed syntax tree
// out. Recursive descent over C's grammar as Dynamic C of 1997 accepted it
// (K&R leftovers included), one function per rule with the rule above it,
// like chibicc's parse.c.
//
// Type checking happens as nodes are built: every expression node gets its
// type, implicit conversions become explicit Cast nodes, pointer arithmetic is
// scaled here, and constant subtrees are folded at once (so case labels,
// array sizes and enum values are plain numbers). Calls to functions whose
// parameters are not yet known (implicit declarations, "int f();") pass
// promoted arguments and are checked against the definition when it arrives.
//
// Robustness: recursion is capped ("nesting too deep"), and so is the height
// of the trees that left-associative loops build ("expression too complex"),
// so the code generator's recursion is bounded too.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include "compiler/ast.h"
#include "vm/bytecode.h"
#include "vm/image.h"

namespace simbot::compiler {

namespace {

constexpr int kMaxDepth = 200;       // nested parens, blocks, unary operators, ...
constexpr int kMaxTreeDepth = 1000;  // height of an expression tree
constexpr int kMaxTypeDepth = 64;    // pointer/array derivations of one type
// Counts a file could make long; each is far beyond what the era's programs
// use (and, for parameters, what fits the expression stack of a call).
constexpr size_t kMaxParameters = 64;
constexpr size_t kMaxMembers = 512;
constexpr int kMaxEnumerators = 4096;

const std::unordered_set<std::string_view> kKeywords = {
    "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else", "enum",
    "extern", "float", "for", "goto", "if", "int", "long", "register", "return", "short", "signed",
    "sizeof", "static", "struct", "switch", "typedef", "union", "unsigned", "void", "volatile",
    "while", "interrupt", "reti", "nodebug", "debug", "shared", "protected", "root", "xmem",
    // Dynamic C's costatement words
    "costate", "waitfor", "yield", "abort", "always_on", "init_on", "wfd", "waitfordone"};

const std::unordered_set<std::string_view> kDeclWords = {
    "void",   "char",     "short",     "int",   "long",     "float",   "double",
    "signed", "unsigned", "struct",    "union", "enum",     "typedef", "static",
    "extern", "auto",     "register",  "const", "volatile", "shared",  "protected",
    "root",   "xmem",     "interrupt", "reti",  "nodebug",  "debug"};

int64_t wrapTo(int64_t v, const Type* t) {
  switch (t->kind) {
    case TypeKind::Char:
      return v & 0xFF;
    case TypeKind::Int:
      return static_cast<int16_t>(static_cast<uint16_t>(v & 0xFFFF));
    case TypeKind::Long:
      return static_cast<int32_t>(static_cast<uint32_t>(v & 0xFFFFFFFF));
    case TypeKind::ULong:
      return v & 0xFFFFFFFF;
    default:
      return v & 0xFFFF;  // unsigned, pointers
  }
}

Type* promote(Type* t) { return t->kind == TypeKind::Char ? tyInt() : t; }

// The usual arithmetic conversions.
Type* commonType(Type* a, Type* b) {
  a = promote(a);
  b = promote(b);
  if (a->kind == TypeKind::Float || b->kind == TypeKind::Float) return tyFloat();
  if (a->kind == TypeKind::ULong || b->kind == TypeKind::ULong) return tyULong();
  if (a->kind == TypeKind::Long || b->kind == TypeKind::Long) return tyLong();
  if (a->kind == TypeKind::UInt || b->kind == TypeKind::UInt) return tyUInt();
  return tyInt();
}

const char* opSpelling(NodeKind k) {
  switch (k) {
    case NodeKind::Add:
      return "+";
    case NodeKind::Sub:
      return "-";
    case NodeKind::Mul:
      return "*";
    case NodeKind::Div:
      return "/";
    case NodeKind::Mod:
      return "%";
    case NodeKind::BitAnd:
      return "&";
    case NodeKind::BitOr:
      return "|";
    case NodeKind::BitXor:
      return "^";
    case NodeKind::Shl:
      return "<<";
    case NodeKind::Shr:
      return ">>";
    case NodeKind::Eq:
      return "==";
    case NodeKind::Ne:
      return "!=";
    case NodeKind::Lt:
      return "<";
    case NodeKind::Le:
      return "<=";
    case NodeKind::Gt:
      return ">";
    case NodeKind::Ge:
      return ">=";
    case NodeKind::LogAnd:
      return "&&";
    case NodeKind::LogOr:
      return "||";
    default:
      return "?";
  }
}

bool isConst(const Node* n) { return n->kind == NodeKind::Num || n->kind == NodeKind::FNum; }
bool truthy(const Node* n) { return n->kind == NodeKind::Num ? n->ival != 0 : n->fval != 0; }

// The jump a statement ends with ("return", ...), or null if control can
// fall out of it. Blocks and ifs count as falling out (no warning is the
// safe side).
const char* endsPath(const Node* n) {
  switch (n->kind) {
    case NodeKind::Return:
      return "return";
    case NodeKind::Break:
      return "break";
    case NodeKind::Continue:
      return "continue";
    case NodeKind::Goto:
      return "goto";
    case NodeKind::Case:
    case NodeKind::Label:
      return n->then ? endsPath(n->then) : nullptr;
    default:
      return nullptr;
  }
}

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
  void leaveScope() { scopes_.pop_back(); }
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
  bool atFunctionDefinition();
  [[noreturn]] void undeclared(Pos pos, const std::string& name, const std::string& message);

  // ---- warnings ----
  void checkCondition(const Node* cond);
  void checkTypeLimits(NodeKind k, const Node* l, const Node* r, Pos pos);

  // ---- statements ----
  Node* statement();
  Node* compoundStatement(bool newScope);
  Node* exprStatement();

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
  Node* libcall(const Token& nameTok, int lib);
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

// ===================================================================
// Token cursor. Pragma tokens (#class, #nodebug) are applied when the cursor
// moves over them, so lookahead never applies them early.

const Token& Parser::at(size_t idx) {
  while (toks_.size() <= idx) {
    if (!toks_.empty() && toks_.back().kind == TokKind::Eof) return toks_.back();
    try {
      toks_.push_back(pp_.next());
    } catch (const CompileError& e) {
      diags_.fatal(e.pos, e.message);  // the token stream ends here
    }
  }
  return toks_[idx];
}

void Parser::settle() {
  while (at(i_).kind == TokKind::Pragma) {
    applyPragma(toks_[i_]);
    ++i_;
  }
}

void Parser::advance() {
  const Token& t = cur();
  if (t.kind == TokKind::Eof) return;
  if (t.kind == TokKind::Punct) {
    if (t.text == "{") {
      ++braceDepth_;
      // A function body's brace follows its ")" or its K&R parameters' ";"
      // (or a parameter list whose ")" is missing).
      braceIsBody_.push_back(parenDepth_ > 0 ||
                             (i_ > 0 && (toks_[i_ - 1].is(")") || toks_[i_ - 1].is(";"))));
    } else if (t.text == "}") {
      braceDepth_ = std::max(0, braceDepth_ - 1);
      lastCloseWasBody_ = braceIsBody_.empty() || braceIsBody_.back();  // empty: unbalanced
      if (!braceIsBody_.empty()) braceIsBody_.pop_back();
    } else if (t.text == "(")
      ++parenDepth_;
    else if (t.text == ")")
      parenDepth_ = std::max(0, parenDepth_ - 1);
  }
  prevPos_ = t.pos;
  ++i_;
  settle();
}

const Token& Parser::peek(int k) {
  size_t j = i_;
  int n = 0;
  for (;;) {
    const Token& t = at(j);
    if (t.kind == TokKind::Eof) return t;
    if (t.kind != TokKind::Pragma) {
      if (n == k) return t;
      ++n;
    }
    ++j;
  }
}

bool Parser::accept(std::string_view s) {
  if (!is(s)) return false;
  advance();
  return true;
}

void Parser::expect(std::string_view s) {
  if (accept(s)) return;
  if (cur().kind == TokKind::Eof)
    fail(after(prevPos_), "expected '" + std::string(s) + "' at end of input");
  fail(cur().pos, "expected '" + std::string(s) + "'");
}

void Parser::expectSemi(const std::string& what) {
  if (accept(";")) return;
  fail(after(prevPos_), "expected ';' " + what);
}

void Parser::applyPragma(const Token& t) {
  if (t.text == "class auto")
    classAuto_ = true;
  else if (t.text == "class static")
    classAuto_ = false;
  else if (t.text == "nodebug")
    nodebugPragma_ = true;
  else if (t.text == "debug")
    nodebugPragma_ = false;
}

// ===================================================================
// Scopes and arenas.

ScopeEntry* Parser::findVar(const std::string& name) {
  for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it) {
    auto f = it->vars.find(name);
    if (f != it->vars.end()) return &f->second;
  }
  return nullptr;
}

Type* Parser::findTag(const std::string& name) {
  for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it) {
    auto f = it->tags.find(name);
    if (f != it->tags.end()) return f->second;
  }
  return nullptr;
}

Type* Parser::typedefOf(const Token& t) {
  if (t.kind != TokKind::Ident || kKeywords.count(t.text)) return nullptr;
  ScopeEntry* e = findVar(t.text);
  return e ? e->typeDef : nullptr;
}

bool Parser::isDeclStart(const Token& t) {
  if (t.kind != TokKind::Ident) return false;
  return kDeclWords.count(t.text) || typedefOf(t) != nullptr;
}

Node* Parser::newNode(NodeKind k, Pos pos, Type* ty) {
  Node& n = prog_.nodes.emplace_back();
  n.kind = k;
  n.pos = pos;
  n.type = ty;
  return &n;
}

Type* Parser::newType(TypeKind k, int size) {
  Type& t = prog_.types.emplace_back();
  t.kind = k;
  t.size = size;
  return &t;
}

Type* Parser::pointerTo(Type* base, Pos pos) {
  if (base->kind == TypeKind::Func) fail(pos, "function pointers are not supported");
  Type* t = newType(TypeKind::Ptr, 2);
  t->base = base;
  t->depth = base->depth + 1;
  if (t->depth > kMaxTypeDepth) fail(pos, "nesting too deep");
  return t;
}

Type* Parser::arrayOf(Type* base, int len, Pos pos) {
  if (base->kind == TypeKind::Func) fail(pos, "array of functions is not allowed");
  if (base->kind == TypeKind::Void) fail(pos, "array has incomplete element type 'void'");
  if (isStructLike(base) && !base->complete)
    fail(pos, "array has incomplete element type '" + typeName(base) + "'");
  if (base->kind == TypeKind::Array && base->arrayLen < 0)
    fail(pos, "array has incomplete element type '" + typeName(base) + "'");
  int64_t size = static_cast<int64_t>(base->size) * (len < 0 ? 0 : len);
  if (size > 0xFFFF) fail(pos, "array is too large");
  Type* t = newType(TypeKind::Array, static_cast<int>(size));
  t->base = base;
  t->arrayLen = len;
  t->depth = base->depth + 1;
  if (t->depth > kMaxTypeDepth) fail(pos, "nesting too deep");
  return t;
}

Obj* Parser::newObj(const std::string& name, Type* ty, Pos pos, Storage st) {
  Obj& o = prog_.objs.emplace_back();
  o.name = name;
  o.symName = name;
  o.type = ty;
  o.pos = pos;
  o.storage = st;
  return &o;
}

Init* Parser::newInit(Type* ty) {
  Init& i = prog_.inits.emplace_back();
  i.type = ty;
  return &i;
}

// ===================================================================
// Declarations.

// program = (";" | external-declaration)*
void Parser::run() {
  enterScope();  // predefined names, shadowable by the program
  for (auto [name, value] : {std::pair<const char*, int>{"PIODA", vm::kPortPIODA},
                             {"PIODB", vm::kPortPIODB},
                             {"PIOCA", vm::kPortPIOCA},
                             {"PIOCB", vm::kPortPIOCB},
                             {"ENB485", vm::kPortENB485},
                             {"PIOA_VEC", vm::kVecPIOA}}) {
    ScopeEntry e;
    e.isConst = true;
    e.value = value;
    scopes_[0].vars[name] = e;
  }
  predefineCostateNames();
  enterScope();  // file scope
  settle();
  while (cur().kind != TokKind::Eof) {
    if (accept(";")) continue;
    Resume r = resumePoint();
    try {
      externalDeclaration();
    } catch (const CompileError& e) {
      recordError(e);
      skipExternalDeclaration();
      poisonSince(r.token);
    } catch (const BackToFileLevel&) {
      braceDepth_ = parenDepth_ = 0;
      braceIsBody_.clear();
    }
    scopes_.resize(2);
    switches_.clear();
    fn_ = nullptr;
    loopDepth_ = breakDepth_ = 0;
  }

  // Whole-program checks: each is an error of its own, none stops the rest.
  const auto check = [this](Pos pos, const std::string& name, std::string message) {
    if (!poisoned_.count(name)) diags_.error(pos, std::move(message));
  };
  for (Function& f : prog_.funcs)
    if (f.called && !f.defined) check(f.firstCall, f.name, "undefined function '" + f.name + "'");

  // #INT_VEC bindings.
  for (const IntVecDirective& d : pp_.intVecs()) {
    auto it = scopes_[1].vars.find(d.name);
    Obj* o = it == scopes_[1].vars.end() ? nullptr : it->second.var;
    if (o && o->storage != Storage::Function) {
      check(d.namePos, d.name, "'" + d.name + "' is not an interrupt function");
      continue;
    }
    if (!o || !o->fn->defined) {
      check(d.namePos, d.name, "undefined interrupt function '" + d.name + "'");
      continue;
    }
    if (!o->fn->isHandler) {
      check(d.namePos, d.name, "'" + d.name + "' is not an interrupt function");
      continue;
    }
    bool bound = false;
    for (const IntVecBinding& b : prog_.vectors)
      if (b.vector == d.vector) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "0x%02X", d.vector);
        diags_.error(d.pos, std::string("interrupt vector ") + buf + " is already bound");
        bound = true;
        break;
      }
    if (!bound) prog_.vectors.push_back(IntVecBinding{d.vector, o->fn, d.pos});
  }
  // A handler nothing binds never runs: the thesis's "#define INT_VEC" slip.
  for (Function* f : prog_.functions) {
    if (!f->isHandler) continue;
    bool bound = false;
    for (const IntVecDirective& d : pp_.intVecs()) bound = bound || d.name == f->name;
    if (!bound)
      diags_.warn(f->defPos, "unbound-handler",
                  "interrupt function '" + f->name +
                      "' is never bound to a vector (no '#INT_VEC VECTOR " + f->name +
                      "'), so it never runs");
  }

  auto it = scopes_[1].vars.find("main");
  Obj* m = it == scopes_[1].vars.end() ? nullptr : it->second.var;
  if (!m || m->storage != Storage::Function || !m->fn->defined) {
    check(Pos{1, 1, 1}, "main", "no main function");
    return;
  }
  if (m->fn->isHandler) diags_.error(m->fn->defPos, "'main' cannot be an interrupt function");
  if (!m->fn->params.empty()) diags_.error(m->fn->defPos, "'main' must not take parameters");
  prog_.main = m->fn;
}

// ===================================================================
// Error recovery (panic mode, as in the Dragon Book 4.1.4): drop the rest of
// the failed statement or declaration and resume at the next one.

Parser::Resume Parser::resumePoint() {
  return Resume{i_,         braceDepth_, parenDepth_, scopes_.size(), switches_.size(),
                loopDepth_, breakDepth_};
}

void Parser::recordError(const CompileError& e) {
  if (!e.silent) diags_.error(e.pos, e.message);
}

// Inside a block: up to and including the ';' that ends the statement at the
// block's own nesting, or through the '}' that closes a block the statement
// opened, or up to (not including) the '}' that ends the enclosing block.
// An "else" right after is part of the same statement.
void Parser::skipStatement(const Resume& r) {
  for (;;) {
    const Token& t = cur();
    if (t.kind == TokKind::Eof) return;
    if (t.is("}") && braceDepth_ <= r.braces) break;
    const bool semi = t.is(";"), close = t.is("}");
    advance();
    if (braceDepth_ != r.braces) continue;
    if (close || (semi && parenDepth_ <= r.parens)) {
      if (is("else")) {
        advance();
        continue;
      }
      break;
    }
  }
  parenDepth_ = r.parens;
}

// At file level: through the ';' or the function body's '}' that ends it
// (an unbalanced '}' ends it too).
void Parser::skipExternalDeclaration() {
  for (;;) {
    const Token& t = cur();
    if (t.kind == TokKind::Eof) break;
    const bool semi = t.is(";"), close = t.is("}");
    advance();
    // A struct's or an initialiser's "}" leaves the declaration's ";" to come.
    if (braceDepth_ == 0 && (semi || (close && lastCloseWasBody_))) break;
  }
  parenDepth_ = 0;
}

// The names a failed declaration was declaring: identifiers outside any
// brackets, and outside initialisers.
void Parser::poisonSince(size_t token) {
  int depth = 0;
  bool inInit = false;
  for (size_t k = token; k < i_ && k < toks_.size(); ++k) {
    const Token& t = toks_[k];
    if (t.is("(") || t.is("[") || t.is("{")) ++depth;
    if (t.is(")") || t.is("]") || t.is("}")) depth = std::max(0, depth - 1);
    if (depth == 0 && t.is("=")) inInit = true;
    if (depth == 0 && t.is(",")) inInit = false;
    if (depth == 0 && !inInit && t.kind == TokKind::Ident && !isKeyword(t))
      poisoned_.insert(t.text);
  }
}

// Reported once per function, as gcc does: the other uses say nothing new.
// At column 1, "NAME ( PARAMS ) {", "TYPE NAME ( PARAMS ) {", "NAME (
// PARAMS ) TYPE" (K&R parameters) or "interrupt", PARAMS holding only
// names, type words, '*', ',' and '[ N ]': never a statement, always a
// function definition; seen inside a block, the block's '}' is missing.
// (A mistyped "if (x == 1) {" has an operator inside and is no match.)
bool Parser::atFunctionDefinition() {
  // The tokens ahead, pragmas skipped, read once each (a long argument list
  // costs its length, not its square).
  std::vector<const Token*> ahead;
  for (size_t j = i_; ahead.size() < 200; ++j) {
    const Token& t = at(j);
    if (t.kind == TokKind::Pragma) continue;
    ahead.push_back(&t);
    if (t.kind == TokKind::Eof || t.is(";") || t.is("{") || t.is("}")) break;
  }
  // The token after the run read so far (Eof or a ';' ... ends the run).
  const auto tok = [&](size_t k) -> const Token& { return *ahead[std::min(k, ahead.size() - 1)]; };
  if (tok(0).pos.col != 1) return false;
  if (tok(0).is("interrupt")) {
    functionNameAhead_.clear();
    for (size_t k = 1; k < ahead.size(); ++k)
      if (tok(k).kind == TokKind::Ident && !isKeyword(tok(k))) {
        functionNameAhead_ = tok(k).text;
        break;
      }
    return true;
  }
  size_t k = 0;
  while (k < ahead.size() &&
         (tok(k).is("*") || (tok(k).kind == TokKind::Ident && kDeclWords.count(tok(k).text))))
    ++k;
  const Token& name = tok(k);
  if (name.kind != TokKind::Ident || isKeyword(name) || !tok(k + 1).is("(")) return false;
  int depth = 0;
  for (size_t j = k + 1; j + 1 < ahead.size(); ++j) {
    const Token& t = tok(j);
    if (!(t.kind == TokKind::Ident || t.kind == TokKind::Number || t.is("(") || t.is(")") ||
          t.is(",") || t.is("*") || t.is("[") || t.is("]") || t.is("...")))
      return false;
    if (tok(j).is("(")) ++depth;
    if (tok(j).is(")") && --depth == 0) {
      const Token& next = tok(j + 1);
      if (!next.is("{") && !(next.kind == TokKind::Ident && kDeclWords.count(next.text)))
        return false;
      functionNameAhead_ = name.text;
      return true;
    }
  }
  return false;
}

void Parser::undeclared(Pos pos, const std::string& name, const std::string& message) {
  const bool again = !undeclaredHere_.insert(name).second;
  throw CompileError{pos, message, again || poisoned_.count(name) > 0};
}

// external-declaration = declspec? declarator ("," declarator)* ";"
//                      | declspec? declarator kr-params? compound-stmt
//                      | declspec ";"
// (no declspec: K&R implicit int, as in "main()")
void Parser::externalDeclaration() {
  VarAttr attr;
  Type* base;
  const Token& t = cur();
  if (t.is("cofunc") || t.is("scofunc") || t.is("firsttime") || t.is("slice")) notSupported(t);
  if (isDeclStart(t)) {
    base = declspec(&attr);
  } else if (t.kind == TokKind::Ident && !isKeyword(t) && peek(1).is("(")) {
    base = tyInt();
  } else if (t.kind == TokKind::Ident && !isKeyword(t) &&
             (peek(1).kind == TokKind::Ident || peek(1).is("*"))) {
    fail(t.pos, "unknown type name '" + t.text + "'");
  } else if (t.is("}")) {
    fail(t.pos, "unbalanced '}'");
  } else {
    fail(t.pos, "expected a declaration");
  }
  if (attr.isInterrupt && !attr.sawType) base = tyVoid();

  if (accept(";")) return;  // "struct s { ... };"
  Declarator first;
  declarator(base, first);
  if (attr.isTypedef) {
    typedefs(base, first);
    return;
  }
  Declarator d = first;
  for (bool isFirst = true;; isFirst = false) {
    if (!d.hasName) fail(d.pos, "expected identifier");
    if (d.type->kind == TypeKind::Func) {
      if (isFirst && (is("{") || (d.type->krNames && isDeclStart(cur())))) {
        functionDefinition(d, attr);
        return;
      }
      if (d.type->krNames && !d.type->params.empty())
        fail(d.pos, "parameter names without types in a function declaration");
      declareFunction(d, attr);
    } else {
      if (attr.isInterrupt) fail(d.pos, "'interrupt' applies only to functions");
      globalVariable(d, attr);
    }
    if (!accept(",")) break;
    d = Declarator{};
    declarator(base, d);
  }
  expectSemi("after declaration");
}

// declspec = ("void" | "char" | "short" | "int" | "long" | "float" | "double"
//            | "signed" | "unsigned" | struct-decl | union-decl | enum-specifier
//            | typedef-name | "typedef" | "static" | "extern" | "auto"
//            | "register" | "const" | "volatile" | "shared" | "protected"
//            | "root" | "xmem" | "interrupt" | "reti" | "nodebug" | "debug")+
// No type word means int (K&R: "register x;", "static y = 1;").
Type* Parser::declspec(VarAttr* attr) {
  enum : int {
    VOID = 1 << 0,
    CHAR = 1 << 2,
    SHORT = 1 << 4,
    INT = 1 << 6,
    LONG = 1 << 8,
    FLOAT = 1 << 10,
    DOUBLE = 1 << 12,
    OTHER = 1 << 14,
    SIGNED = 1 << 16,
    UNSIGNED = 1 << 18,
  };
  Type* ty = tyInt();
  int counter = 0;
  for (;;) {
    const Token& t = cur();
    if (t.kind != TokKind::Ident) break;
    Pos pos = t.pos;
    const std::string& w = t.text;
    if (w == "typedef" || w == "static" || w == "extern" || w == "auto" || w == "register") {
      if (!attr) fail(pos, "storage class specifier '" + w + "' is not allowed here");
      if (attr->sawStorage && !(w == "register" || attr->isRegister))
        fail(pos, "multiple storage classes in declaration");
      attr->sawStorage = true;
      if (w == "typedef")
        attr->isTypedef = true;
      else if (w == "static")
        attr->isStatic = true;
      else if (w == "extern")
        attr->isExtern = true;
      else if (w == "auto")
        attr->isAuto = true;
      else
        attr->isRegister = true;
      advance();
      continue;
    }
    if (w == "const" || w == "volatile" || w == "shared" || w == "protected" || w == "root" ||
        w == "xmem") {
      advance();
      continue;
    }
    if (w == "interrupt" || w == "reti" || w == "nodebug" || w == "debug") {
      if (!attr) fail(pos, "'" + w + "' is not allowed here");
      if (w == "interrupt" || w == "reti")
        attr->isInterrupt = true;
      else if (w == "nodebug")
        attr->nodebug = true;
      else
        attr->debug = true;
      advance();
      continue;
    }
    Type* td = typedefOf(t);
    if (!kDeclWords.count(w) && !td) break;
    if (td) {
      if (counter) break;  // a second name is the declarator
      ty = td;
      counter += OTHER;
      advance();
      continue;
    }
    if (w == "struct" || w == "union" || w == "enum") {
      if (counter) fail(pos, "invalid combination of type specifiers");
      advance();
      ty = w == "enum" ? enumSpecifier() : structDecl(w == "union");
      counter += OTHER;
      continue;
    }
    if (w == "void")
      counter += VOID;
    else if (w == "char")
      counter += CHAR;
    else if (w == "short")
      counter += SHORT;
    else if (w == "int")
      counter += INT;
    else if (w == "long") {
      if (counter & LONG) fail(pos, "long long is not supported");
      counter += LONG;
    } else if (w == "float")
      counter += FLOAT;
    else if (w == "double")
      counter += DOUBLE;
    else if (w == "signed")
      counter |= SIGNED;
    else if (w == "unsigned")
      counter |= UNSIGNED;

    switch (counter) {
      case VOID:
        ty = tyVoid();
        break;
      case CHAR:
      case SIGNED + CHAR:
      case UNSIGNED + CHAR:
        ty = tyChar();
        break;
      case SHORT:
      case SHORT + INT:
      case SIGNED + SHORT:
      case SIGNED + SHORT + INT:
      case INT:
      case SIGNED:
      case SIGNED + INT:
        ty = tyInt();
        break;
      case UNSIGNED + SHORT:
      case UNSIGNED + SHORT + INT:
      case UNSIGNED:
      case UNSIGNED + INT:
        ty = tyUInt();
        break;
      case LONG:
      case LONG + INT:
      case SIGNED + LONG:
      case SIGNED + LONG + INT:
        ty = tyLong();
        break;
      case UNSIGNED + LONG:
      case UNSIGNED + LONG + INT:
        ty = tyULong();
        break;
      case FLOAT:
      case DOUBLE:
      case LONG + DOUBLE:
        ty = tyFloat();
        break;
      default:
        fail(pos, "invalid combination of type specifiers");
    }
    advance();
  }
  if (attr) attr->sawType = counter != 0;
  return ty;
}

// struct-decl = ident? ("{" (declspec declarator ("," declarator)* ";")* "}")?
Type* Parser::structDecl(bool isUnion) {
  DepthGuard guard(*this);
  std::string tag;
  Pos pos = cur().pos;
  if (cur().kind == TokKind::Ident && !isKeyword(cur())) {
    tag = cur().text;
    advance();
  }
  const char* word = isUnion ? "union" : "struct";
  TypeKind kind = isUnion ? TypeKind::Union : TypeKind::Struct;
  if (!is("{")) {
    if (tag.empty()) fail(cur().pos, std::string("expected '{' or a tag after '") + word + "'");
    Type* t = findTag(tag);
    if (t) {
      if (t->kind != kind)
        fail(pos, "use of '" + tag + "' with tag type that does not match previous declaration");
      return t;
    }
    t = newType(kind, 0);
    t->tag = tag;
    t->complete = false;
    scopes_.back().tags[tag] = t;
    return t;
  }
  advance();
  Type* t = nullptr;
  if (!tag.empty()) {
    auto it = scopes_.back().tags.find(tag);
    if (it != scopes_.back().tags.end()) {
      t = it->second;
      if (t->kind != kind)
        fail(pos, "use of '" + tag + "' with tag type that does not match previous declaration");
      if (t->complete) fail(pos, std::string("redefinition of '") + word + " " + tag + "'");
    }
  }
  if (!t) {
    t = newType(kind, 0);
    t->tag = tag;
    if (!tag.empty()) scopes_.back().tags[tag] = t;
  }
  t->complete = false;
  int offset = 0, size = 0;
  while (!accept("}")) {
    if (cur().kind == TokKind::Eof) fail(after(prevPos_), "expected '}' at end of input");
    VarAttr attr;
    Type* base = declspec(&attr);
    if (attr.sawStorage || attr.isInterrupt) fail(cur().pos, "storage class in a struct member");
    for (bool first = true; !accept(";"); first = false) {
      if (!first) expect(",");
      Declarator d;
      declarator(base, d);
      if (is(":")) fail(cur().pos, "bit-fields are not supported");
      if (!d.hasName) fail(d.pos, "expected member name");
      if (d.type->kind == TypeKind::Func)
        fail(d.pos, "member '" + d.name + "' declared as a function");
      if (d.type->kind == TypeKind::Void || (isStructLike(d.type) && !d.type->complete) ||
          (d.type->kind == TypeKind::Array && d.type->arrayLen < 0))
        fail(d.pos, "member '" + d.name + "' has incomplete type");
      if (t->members.size() >= kMaxMembers)
        fail(d.pos, fmt::format("too many members in one {} (at most {})", word, kMaxMembers));
      for (const Member& m : t->members)
        if (m.name == d.name) fail(d.pos, "duplicate member '" + d.name + "'");
      // Packed: the Z180 has no alignment rules.
      t->members.push_back(Member{d.name, d.type, isUnion ? 0 : offset});
      offset += d.type->size;
      size = std::max(size, d.type->size);
      if (offset > 0xFFFF) fail(d.pos, std::string(word) + " is too large");
    }
  }
  t->size = isUnion ? size : offset;
  t->complete = true;
  return t;
}

// enum-specifier = ident? "{" ident ("=" const-expr)? ("," ident ("=" const-expr)?)* ","? "}"
//                | ident
Type* Parser::enumSpecifier() {
  std::string tag;
  if (cur().kind == TokKind::Ident && !isKeyword(cur())) {
    tag = cur().text;
    advance();
  }
  if (!is("{")) {
    if (tag.empty()) fail(cur().pos, "expected '{' or a tag after 'enum'");
    return tyInt();  // enums are ints; an unknown tag is accepted as K&R compilers did
  }
  advance();
  int64_t next = 0;
  bool first = true;
  int enumerators = 0;
  while (!accept("}")) {
    if (!first) {
      expect(",");
      if (accept("}")) break;
    }
    first = false;
    const Token& t = cur();
    if (t.kind != TokKind::Ident || isKeyword(t)) fail(t.pos, "expected identifier in enum");
    if (++enumerators > kMaxEnumerators)
      fail(t.pos, fmt::format("too many enumerators in one enum (at most {})", kMaxEnumerators));
    std::string name = t.text;
    Pos pos = t.pos;
    advance();
    if (accept("=")) next = constExpr();
    if (next < -32768 || next > 65535) fail(pos, "enumerator value is out of range");
    if (scopes_.back().vars.count(name)) fail(pos, "redefinition of '" + name + "'");
    ScopeEntry e;
    e.isConst = true;
    e.value = wrapTo(next, tyInt());
    scopes_.back().vars[name] = e;
    ++next;
  }
  return tyInt();
}

// declarator = ("*" qualifier*)* ("(" declarator ")" | ident)? type-suffix
void Parser::declarator(Type* ty, Declarator& d) {
  DepthGuard guard(*this);
  d.pos = cur().pos;
  while (is("*")) {
    ty = pointerTo(ty, cur().pos);
    advance();
    while (is("const") || is("volatile")) advance();
  }
  if (is("(") && peek(1).is("*")) {
    // Nested declarator, e.g. "(*p)[3]": the suffix after ")" applies first.
    size_t start = i_;
    advance();
    Declarator dummy;
    declarator(tyInt(), dummy);
    expect(")");
    ty = typeSuffix(ty);
    size_t end = i_;
    Pos endPrev = prevPos_;
    i_ = start;
    advance();
    declarator(ty, d);
    i_ = end;
    prevPos_ = endPrev;
    return;
  }
  if (cur().kind == TokKind::Ident && !isKeyword(cur())) {
    d.name = cur().text;
    d.pos = cur().pos;
    d.hasName = true;
    advance();
  } else if (isKeyword(cur()) && !is("sizeof")) {
    d.pos = cur().pos;
  }
  d.type = typeSuffix(ty);
}

// type-suffix = "(" func-params | "[" const-expr? "]" type-suffix | (nothing)
Type* Parser::typeSuffix(Type* ty) {
  DepthGuard guard(*this);
  if (is("(")) return funcParams(ty);
  if (is("[")) {
    Pos pos = cur().pos;
    advance();
    int len = -1;
    if (!is("]")) {
      Pos at = cur().pos;
      int64_t n = constExpr();
      if (n < 0) fail(at, "size of array is negative");
      if (n > 0xFFFF) fail(at, "array is too large");
      len = static_cast<int>(n);
    }
    expect("]");
    Type* elem = typeSuffix(ty);
    return arrayOf(elem, len, pos);
  }
  return ty;
}

// func-params = ")" | "void" ")" | ident ("," ident)* ")"
//             | param ("," param)* ")"          param = declspec declarator
Type* Parser::funcParams(Type* ret) {
  Pos pos = cur().pos;
  advance();  // "("
  if (ret->kind == TypeKind::Array || ret->kind == TypeKind::Func)
    fail(pos, "function cannot return an array or a function");
  if (isStructLike(ret)) fail(pos, "functions returning a struct are not supported");
  Type* fn = newType(TypeKind::Func, 1);
  fn->base = ret;
  fn->depth = ret->depth + 1;
  if (accept(")")) return fn;
  if (is("void") && peek(1).is(")")) {
    advance();
    advance();
    fn->hasProto = true;
    return fn;
  }
  if (cur().kind == TokKind::Ident && !isDeclStart(cur()) && !isKeyword(cur())) {
    // K&R identifier list; the types follow the ")".
    fn->krNames = true;
    for (;;) {
      const Token& t = cur();
      if (t.kind != TokKind::Ident || isKeyword(t)) fail(t.pos, "expected parameter name");
      if (fn->params.size() >= kMaxParameters)
        fail(t.pos, fmt::format("too many parameters (at most {})", kMaxParameters));
      for (const Param& p : fn->params)
        if (p.name == t.text) fail(t.pos, "redefinition of parameter '" + t.text + "'");
      fn->params.push_back(Param{t.text, tyInt(), t.pos, false});
      advance();
      if (accept(")")) return fn;
      expect(",");
    }
  }
  fn->hasProto = true;
  for (;;) {
    if (is("...")) fail(cur().pos, "variadic functions are not supported");
    Pos ppos = cur().pos;
    if (fn->params.size() >= kMaxParameters)
      fail(ppos, fmt::format("too many parameters (at most {})", kMaxParameters));
    if (!isDeclStart(cur())) {
      if (cur().kind == TokKind::Ident && !isKeyword(cur()))
        fail(cur().pos, "unknown type name '" + cur().text + "'");
      fail(cur().pos, "expected parameter declaration");
    }
    VarAttr attr;
    Type* base = declspec(&attr);
    if (attr.isTypedef || attr.isStatic || attr.isExtern || attr.isInterrupt)
      fail(ppos, "invalid storage class for a parameter");
    Declarator d;
    declarator(base, d);
    Type* t = d.type;
    if (t->kind == TypeKind::Array) t = pointerTo(t->base, d.pos);
    if (t->kind == TypeKind::Func) fail(d.pos, "function pointers are not supported");
    if (t->kind == TypeKind::Void) fail(d.hasName ? d.pos : ppos, "parameter has void type");
    if (isStructLike(t))
      fail(d.hasName ? d.pos : ppos, "passing a struct by value is not supported");
    if (d.hasName)
      for (const Param& p : fn->params)
        if (p.name == d.name) fail(d.pos, "redefinition of parameter '" + d.name + "'");
    fn->params.push_back(Param{d.name, t, d.hasName ? d.pos : ppos, attr.isRegister});
    if (accept(")")) return fn;
    expect(",");
  }
}

// type-name = declspec abstract-declarator
Type* Parser::abstractTypeName() {
  Type* base = declspec(nullptr);
  Declarator d;
  declarator(base, d);
  if (d.hasName) fail(d.pos, "unexpected name in type");
  return d.type;
}

// typedef-decl = "typedef" declspec declarator ("," declarator)* ";"
// (the first declarator already parsed)
void Parser::typedefs(Type* base, Declarator& first) {
  Declarator d = first;
  for (;;) {
    if (!d.hasName) fail(d.pos, "expected identifier in typedef");
    auto& vars = scopes_.back().vars;
    auto it = vars.find(d.name);
    if (it != vars.end() && !(it->second.typeDef && sameType(it->second.typeDef, d.type)))
      fail(d.pos, "redefinition of '" + d.name + "'");
    ScopeEntry e;
    e.typeDef = d.type;
    vars[d.name] = e;
    if (!accept(",")) break;
    d = Declarator{};
    declarator(base, d);
  }
  expectSemi("after declaration");
}

// A function declaration or the head of its definition: finds or creates the
// one Function object for the name (file scope) and checks compatibility.
Function* Parser::declareFunction(Declarator& d, const VarAttr& attr) {
  Scope& file = scopes_[1];
  auto it = file.vars.find(d.name);
  if (it != file.vars.end()) {
    ScopeEntry& e = it->second;
    if (!e.var || e.var->storage != Storage::Function)
      fail(d.pos, "'" + d.name + "' redeclared as a different kind of symbol");
    Function* f = e.var->fn;
    if (f->implicit) {
      Slot s = slotOf(d.type->base);
      if (!(s == Slot::Word || s == Slot::Byte || d.type->base->kind == TypeKind::Void))
        fail(d.pos, "conflicting types for '" + d.name + "' (called before as returning int)");
      f->implicit = false;
      f->type = d.type;
    } else if (!sameType(f->type, d.type) && !d.type->krNames) {
      fail(d.pos, "conflicting types for '" + d.name + "'");
    } else if (d.type->hasProto && !f->type->hasProto) {
      f->type = d.type;
    }
    if (attr.isInterrupt) f->isHandler = true;
    return f;
  }
  Obj* o = newObj(d.name, d.type, d.pos, Storage::Function);
  Function& f = prog_.funcs.emplace_back();
  f.obj = o;
  f.name = d.name;
  f.type = d.type;
  f.isHandler = attr.isInterrupt;
  o->fn = &f;
  ScopeEntry e;
  e.var = o;
  file.vars[d.name] = e;
  return &f;
}

// function-definition = declspec? declarator kr-param-decl* compound-stmt
// kr-param-decl = declspec declarator ("," declarator)* ";"
void Parser::functionDefinition(Declarator& d, const VarAttr& attr) {
  if (scopes_.size() != 2) fail(d.pos, "function definition is not allowed here");
  Type* ft = d.type;
  if (ft->krNames) {
    // Old-style parameter declarations: fill in the types, int by default.
    while (!is("{")) {
      VarAttr pattr;
      Pos ppos = cur().pos;
      Type* base = declspec(&pattr);
      if (pattr.isTypedef || pattr.isStatic || pattr.isExtern || pattr.isInterrupt)
        fail(ppos, "invalid storage class for a parameter");
      for (bool first = true; !accept(";"); first = false) {
        if (!first) expect(",");
        Declarator pd;
        declarator(base, pd);
        if (!pd.hasName) fail(pd.pos, "expected parameter name");
        auto p = std::find_if(ft->params.begin(), ft->params.end(),
                              [&](const Param& q) { return q.name == pd.name; });
        if (p == ft->params.end())
          fail(pd.pos, "declaration for parameter '" + pd.name + "' but no such parameter");
        Type* t = pd.type;
        if (t->kind == TypeKind::Array) t = pointerTo(t->base, pd.pos);
        if (t->kind == TypeKind::Func) fail(pd.pos, "function pointers are not supported");
        if (t->kind == TypeKind::Void) fail(pd.pos, "parameter has void type");
        if (isStructLike(t)) fail(pd.pos, "passing a struct by value is not supported");
        p->type = t;
        p->isRegister = pattr.isRegister;
        if (cur().kind == TokKind::Eof) fail(after(prevPos_), "expected '{' at end of input");
      }
    }
    ft->krNames = false;
    ft->hasProto = true;  // a definition tells later calls the parameter types
  }
  if (!ft->hasProto) ft->hasProto = true;  // "f()" defines no parameters

  Function* f = declareFunction(d, attr);
  if (f->defined) fail(d.pos, "redefinition of '" + d.name + "'");
  f->type = ft;
  f->defined = true;
  f->defPos = d.pos;
  if (attr.isInterrupt) f->isHandler = true;
  f->debug = options_.debug && (attr.debug || (!attr.nodebug && !nodebugPragma_));
  if (f->isHandler) {
    if (!ft->params.empty())
      fail(d.pos, "interrupt function '" + d.name + "' cannot have parameters");
    if (ft->base->kind != TypeKind::Void && attr.sawType)
      fail(d.pos, "interrupt function '" + d.name + "' must return void");
    ft->base = tyVoid();
  }
  prog_.functions.push_back(f);

  fn_ = f;
  enterScope();
  for (const Param& p : ft->params) {
    if (p.name.empty()) fail(p.pos, "parameter name omitted");
    bool autoClass = classAuto_;
    Obj* o = newObj(p.name, p.type, p.pos, autoClass ? Storage::Auto : Storage::Static);
    o->symName = f->name + "." + p.name;
    o->isParam = true;
    o->isRegister = p.isRegister;
    ScopeEntry e;
    e.var = o;
    scopes_.back().vars[p.name] = e;
    f->params.push_back(o);
  }
  // Earlier calls made without knowing the parameters.
  for (Node* call : f->uncheckedCalls) checkCallAgainstDefinition(f, call);
  f->uncheckedCalls.clear();

  labels_.clear();
  gotos_.clear();
  undeclaredHere_.clear();
  f->body = compoundStatement(false);
  leaveScope();
  for (Node* g : gotos_)
    if (!labels_.count(g->str)) diags_.error(g->pos, "use of undeclared label '" + g->str + "'");
  fn_ = nullptr;
}

void Parser::checkCallAgainstDefinition(Function* f, Node* call, bool kinds) {
  size_t want = f->type->params.size(), got = call->list.size();
  if (got > want)
    fail(call->pos, "too many arguments to function '" + f->name + "' (expected " +
                        std::to_string(want) + ", got " + std::to_string(got) + ")");
  if (got < want)
    fail(call->pos, "too few arguments to function '" + f->name + "' (expected " +
                        std::to_string(want) + ", got " + std::to_string(got) + ")");
  for (size_t i = 0; kinds && i < got; ++i) {
    Type* passed = call->list[i]->type;
    const Param& p = f->type->params[i];
    if (slotName(passed) != slotName(p.type))
      fail(call->argPos[i], "argument " + std::to_string(i + 1) + " to '" + f->name +
                                "' is passed as '" + typeName(passed) + "' but parameter '" +
                                p.name + "' is '" + typeName(p.type) + "'");
  }
}

void Parser::checkComplete(Obj* obj) {
  Type* t = obj->type;
  if (t->kind == TypeKind::Void) fail(obj->pos, "variable '" + obj->name + "' has void type");
  if (obj->isExtern) return;
  if (t->kind == TypeKind::Array && t->arrayLen < 0)
    fail(obj->pos, "array size missing in '" + obj->name + "'");
  if (isStructLike(t) && !t->complete)
    fail(obj->pos, "storage size of '" + obj->name + "' is not known");
}

// global-variable = declarator ("=" initializer)?
void Parser::globalVariable(Declarator& d, const VarAttr& attr) {
  Scope& file = scopes_[1];
  auto it = file.vars.find(d.name);
  Obj* obj = nullptr;
  if (it != file.vars.end()) {
    ScopeEntry& e = it->second;
    if (!e.var || e.var->storage == Storage::Function)
      fail(d.pos, "'" + d.name + "' redeclared as a different kind of symbol");
    obj = e.var;
    if (!sameType(obj->type, d.type)) fail(d.pos, "conflicting types for '" + d.name + "'");
    if (obj->type->kind == TypeKind::Array && obj->type->arrayLen < 0) obj->type = d.type;
    if (!attr.isExtern && obj->isExtern) {
      obj->isExtern = false;
      obj->pos = d.pos;
    }
  } else {
    obj = newObj(d.name, d.type, d.pos, Storage::Global);
    obj->isExtern = attr.isExtern;
    ScopeEntry e;
    e.var = obj;
    file.vars[d.name] = e;
    prog_.globals.push_back(obj);
  }
  if (accept("=")) {
    if (obj->init) fail(d.pos, "redefinition of '" + d.name + "'");
    obj->isExtern = false;
    Type* t = obj->type;
    obj->init = initializer(t);
    obj->type = t;
  }
  if (!attr.isExtern || obj->init) checkComplete(obj);
}

// declaration = declspec (declarator ("=" initializer)? ("," ...)*)? ";"
// Locals are static unless "#class auto" is in force; "auto" or "static"
// on the declaration overrides it.
void Parser::localDeclaration(std::vector<Node*>& out) {
  VarAttr attr;
  Pos start = cur().pos;
  Type* base = declspec(&attr);
  if (attr.isInterrupt) fail(start, "'interrupt' applies only to functions");
  if (accept(";")) return;
  Declarator d;
  declarator(base, d);
  if (attr.isTypedef) {
    typedefs(base, d);
    return;
  }
  for (;;) {
    if (!d.hasName) fail(d.pos, "expected identifier");
    if (d.type->kind == TypeKind::Func) {
      declareFunction(d, attr);
    } else if (attr.isExtern) {
      // Refers to the global of that name.
      ScopeEntry* g = nullptr;
      auto it = scopes_[1].vars.find(d.name);
      if (it != scopes_[1].vars.end()) g = &it->second;
      Obj* obj;
      if (g && g->var && g->var->storage == Storage::Global) {
        obj = g->var;
        if (!sameType(obj->type, d.type)) fail(d.pos, "conflicting types for '" + d.name + "'");
      } else {
        if (g) fail(d.pos, "'" + d.name + "' redeclared as a different kind of symbol");
        obj = newObj(d.name, d.type, d.pos, Storage::Global);
        obj->isExtern = true;
        ScopeEntry e;
        e.var = obj;
        scopes_[1].vars[d.name] = e;
        prog_.globals.push_back(obj);
      }
      if (scopes_.back().vars.count(d.name)) fail(d.pos, "redefinition of '" + d.name + "'");
      ScopeEntry e;
      e.var = obj;
      scopes_.back().vars[d.name] = e;
      if (is("=")) fail(cur().pos, "'extern' variable cannot have an initializer");
    } else {
      if (scopes_.back().vars.count(d.name)) fail(d.pos, "redefinition of '" + d.name + "'");
      bool isAuto = attr.isAuto || (!attr.isStatic && classAuto_);
      Obj* obj = newObj(d.name, d.type, d.pos, isAuto ? Storage::Auto : Storage::Static);
      obj->symName = fn_->name + "." + d.name;
      obj->isRegister = attr.isRegister;
      ScopeEntry e;
      e.var = obj;
      scopes_.back().vars[d.name] = e;
      fn_->locals.push_back(obj);
      if (accept("=")) {
        Type* t = obj->type;
        Init* init = initializer(t);
        obj->type = t;
        if (isAuto) {
          Node* n = newNode(NodeKind::DeclInit, d.pos);
          n->var = obj;
          n->initv = init;
          out.push_back(n);
        } else {
          obj->init = init;  // applied once, at load
        }
      }
      checkComplete(obj);
    }
    if (!accept(",")) break;
    d = Declarator{};
    declarator(base, d);
  }
  expectSemi("after declaration");
}

// initializer = string-literal | "{" initializer ("," initializer)* ","? "}"
//             | assign
// Arrays of unknown length take their length from the initializer.
Init* Parser::initializer(Type*& ty) {
  Init* init = newInit(ty);
  initializer2(init);
  if (ty->kind == TypeKind::Array && ty->arrayLen < 0) {
    int len = init->expr ? static_cast<int>(init->expr->str.size()) + 1
                         : static_cast<int>(init->children.size());
    ty = arrayOf(ty->base, len, prevPos_);
    init->type = ty;
  }
  return init;
}

bool Parser::atInitEnd() { return is("}") || (is(",") && peek(1).is("}")); }

// initializer2 = string-literal | "{" string-literal ","? "}"   (char arrays)
//              | "{" (initializer2 ("," initializer2)*)? ","? "}"
//              | initializer2 ("," initializer2)*   (braces elided: fills one aggregate)
//              | assign
void Parser::initializer2(Init* init) {
  DepthGuard guard(*this);
  Type* ty = init->type;
  if (ty->kind == TypeKind::Array) {
    bool charArray = ty->base->kind == TypeKind::Char;
    bool braced = is("{");
    if (charArray && (cur().kind == TokKind::String ||
                      (braced && peek(1).kind == TokKind::String &&
                       (peek(2).is("}") || (peek(2).is(",") && peek(3).is("}")))))) {
      if (braced) advance();
      Node* s = primary();  // concatenates adjacent literals
      if (ty->arrayLen >= 0 && static_cast<int>(s->str.size()) > ty->arrayLen)
        fail(s->pos, "initializer string is too long for the array");
      init->expr = s;
      if (braced) {
        accept(",");
        expect("}");
      }
      return;
    }
    if (braced) advance();
    arrayInitializer(init, braced);
    return;
  }
  if (isStructLike(ty)) {
    if (is("{")) {
      advance();
      structInitializer(init, true);
      return;
    }
    // A struct-valued expression, or the members without braces.
    size_t save = i_;
    Pos savePrev = prevPos_;
    Node* e = assign();
    if (e->type == ty) {
      init->expr = e;
      return;
    }
    i_ = save;
    prevPos_ = savePrev;
    structInitializer(init, false);
    return;
  }
  if (is("{")) {
    advance();
    Pos pos = cur().pos;
    init->expr = assignConvert(assign(), ty, pos, "initialization");
    accept(",");
    expect("}");
    return;
  }
  Pos pos = cur().pos;
  Node* e = assign();
  init->expr = assignConvert(e, ty, pos, "initialization");
}

// array-initializer = the elements in order; an array of unknown length takes
// as many as are given (braced only), a known one at most its length.
void Parser::arrayInitializer(Init* init, bool braced) {
  Type* ty = init->type;
  bool flexible = ty->arrayLen < 0;
  for (int i = 0;; ++i) {
    if (braced) {
      if (accept("}")) break;
      if (i > 0) {
        expect(",");
        if (accept("}")) break;
      }
    } else {
      if (i >= ty->arrayLen || atInitEnd() || cur().kind == TokKind::Eof) break;
      if (i > 0) expect(",");
    }
    if (!flexible && i >= ty->arrayLen) fail(cur().pos, "excess elements in array initializer");
    if (cur().kind == TokKind::Eof) fail(after(prevPos_), "expected '}' at end of input");
    Init* c = newInit(ty->base);
    initializer2(c);
    init->children.push_back(c);
    if (init->children.size() > 0xFFFF) fail(cur().pos, "array is too large");
  }
}

// struct-initializer = the members in order (a union: its first member)
void Parser::structInitializer(Init* init, bool braced) {
  Type* ty = init->type;
  if (!ty->complete) fail(cur().pos, "initializing an incomplete type '" + typeName(ty) + "'");
  size_t n =
      ty->kind == TypeKind::Union ? std::min<size_t>(1, ty->members.size()) : ty->members.size();
  for (size_t i = 0;; ++i) {
    if (braced) {
      if (accept("}")) break;
      if (i > 0) {
        expect(",");
        if (accept("}")) break;
      }
    } else {
      if (i >= n || atInitEnd() || cur().kind == TokKind::Eof) break;
      if (i > 0) expect(",");
    }
    if (i >= n) fail(cur().pos, "excess elements in struct initializer");
    if (cur().kind == TokKind::Eof) fail(after(prevPos_), "expected '}' at end of input");
    Init* c = newInit(ty->members[i].type);
    initializer2(c);
    init->children.push_back(c);
  }
}

// ===================================================================
// Statements.

// stmt = "return" expr? ";"
//      | "if" "(" expr ")" stmt ("else" stmt)?
//      | "switch" "(" expr ")" stmt
//      | "case" const-expr ":" stmt
//      | "default" ":" stmt
//      | "for" "(" (declaration | expr? ";") expr? ";" expr? ")" stmt
//      | "while" "(" expr ")" stmt
//      | "do" stmt "while" "(" expr ")" ";"
//      | "goto" ident ";"
//      | "break" ";" | "continue" ";"
//      | ident ":" stmt
//      | "{" compound-stmt
//      | expr? ";"
Node* Parser::statement() {
  DepthGuard guard(*this);
  const Token& t = cur();
  Pos pos = t.pos;

  if (t.is("return")) {
    advance();
    Node* n = newNode(NodeKind::Return, pos);
    Type* ret = fn_->type->base;
    if (!is(";")) {
      Pos epos = cur().pos;
      Node* e = expr();
      if (fn_->isHandler)
        fail(epos, "interrupt function '" + fn_->name + "' cannot return a value");
      if (ret->kind == TypeKind::Void) {
        if (e->type->kind != TypeKind::Void)
          fail(epos, "void function '" + fn_->name + "' should not return a value");
        n->lhs = e;  // "return f();" with f void: evaluated for its effect
      } else {
        n->lhs = assignConvert(e, ret, epos, "return");
      }
    }
    expectSemi("after return statement");
    return n;
  }

  if (t.is("if")) {
    advance();
    Node* n = newNode(NodeKind::If, pos);
    expect("(");
    n->cond = value(expr());
    checkCondition(n->cond);
    if (!isScalar(n->cond->type)) fail(n->cond->pos, "condition must have scalar type");
    expect(")");
    n->then = statement();
    if (accept("else")) n->els = statement();
    return n;
  }

  if (t.is("switch")) {
    advance();
    Node* n = newNode(NodeKind::Switch, pos);
    expect("(");
    Node* sel = value(expr());
    if (!isInteger(sel->type)) fail(sel->pos, "switch quantity is not an integer");
    n->cond = castTo(sel, promote(sel->type), sel->pos);
    expect(")");
    switches_.push_back(n);
    ++breakDepth_;
    n->then = statement();
    --breakDepth_;
    switches_.pop_back();
    return n;
  }

  if (t.is("case") || t.is("default")) {
    bool isDefault = t.is("default");
    advance();
    if (switches_.empty())
      fail(pos,
           isDefault ? "'default' label not within a switch" : "case label not within a switch");
    Node* sw = switches_.back();
    Node* n = newNode(NodeKind::Case, pos);
    n->isDefault = isDefault;
    if (isDefault) {
      for (Node* c : sw->cases)
        if (c->isDefault) fail(pos, "multiple default labels in one switch");
    } else {
      Pos vpos = cur().pos;
      Type* vt = nullptr;
      int64_t v = constExpr(&vt);
      v = wrapTo(v, sw->cond->type);
      for (Node* c : sw->cases)
        if (!c->isDefault && c->ival == v) fail(vpos, "duplicate case value " + std::to_string(v));
      n->ival = v;
    }
    expect(":");
    sw->cases.push_back(n);
    n->then = statement();
    return n;
  }

  if (t.is("for")) {
    advance();
    Node* n = newNode(NodeKind::For, pos);
    expect("(");
    enterScope();
    if (isDeclStart(cur())) {
      std::vector<Node*> inits;
      localDeclaration(inits);
      Node* b = newNode(NodeKind::Block, pos);
      b->list = std::move(inits);
      n->init = b;
    } else if (!accept(";")) {
      Node* e = exprStatement();
      n->init = e;
    }
    if (!is(";")) {
      n->cond = value(expr());
      checkCondition(n->cond);
      if (!isScalar(n->cond->type)) fail(n->cond->pos, "condition must have scalar type");
    }
    expectSemi("in 'for'");
    if (!is(")")) {
      Node* e = expr();
      Node* s = newNode(NodeKind::ExprStmt, e->pos);
      s->lhs = e;
      n->inc = s;
    }
    expect(")");
    ++loopDepth_;
    ++breakDepth_;
    n->then = statement();
    --loopDepth_;
    --breakDepth_;
    leaveScope();
    return n;
  }

  if (t.is("while")) {
    advance();
    Node* n = newNode(NodeKind::While, pos);
    expect("(");
    n->cond = value(expr());
    checkCondition(n->cond);
    if (!isScalar(n->cond->type)) fail(n->cond->pos, "condition must have scalar type");
    expect(")");
    ++loopDepth_;
    ++breakDepth_;
    n->then = statement();
    --loopDepth_;
    --breakDepth_;
    return n;
  }

  if (t.is("do")) {
    advance();
    Node* n = newNode(NodeKind::DoWhile, pos);
    ++loopDepth_;
    ++breakDepth_;
    n->then = statement();
    --loopDepth_;
    --breakDepth_;
    if (!is("while"))
      fail(cur().kind == TokKind::Eof ? after(prevPos_) : cur().pos,
           "expected 'while' in do/while loop");
    advance();
    expect("(");
    n->cond = value(expr());
    checkCondition(n->cond);
    if (!isScalar(n->cond->type)) fail(n->cond->pos, "condition must have scalar type");
    expect(")");
    expectSemi("after do/while statement");
    return n;
  }

  if (t.is("goto")) {
    advance();
    if (cur().kind != TokKind::Ident || isKeyword(cur()))
      fail(cur().pos, "expected label name after 'goto'");
    Node* n = newNode(NodeKind::Goto, cur().pos);
    n->str = cur().text;
    advance();
    gotos_.push_back(n);
    expectSemi("after 'goto'");
    return n;
  }

  if (t.is("break")) {
    advance();
    if (breakDepth_ == 0 && !costates_.empty())
      fail(pos, "'break' cannot leave a costatement (use 'abort' to end its pass)");
    if (breakDepth_ == 0) fail(pos, "break statement not in loop or switch");
    expectSemi("after 'break'");
    return newNode(NodeKind::Break, pos);
  }

  if (t.is("continue")) {
    advance();
    if (loopDepth_ == 0 && !costates_.empty())
      fail(pos, "'continue' cannot leave a costatement (use 'yield' to give way)");
    if (loopDepth_ == 0) fail(pos, "continue statement not in loop");
    expectSemi("after 'continue'");
    return newNode(NodeKind::Continue, pos);
  }

  if (t.kind == TokKind::Ident && !isKeyword(t) && peek(1).is(":")) {
    Node* n = newNode(NodeKind::Label, pos);
    n->str = t.text;
    if (labels_.count(t.text)) fail(pos, "redefinition of label '" + t.text + "'");
    labels_[t.text] = n;
    advance();
    advance();
    n->then = statement();
    return n;
  }

  if (t.is("costate")) return costateStatement();
  if (t.is("waitfor")) return waitforStatement();
  if (t.is("yield")) return costateControl(NodeKind::Yield);
  if (t.is("abort")) return costateControl(NodeKind::Abort);
  if (t.is("wfd") || t.is("waitfordone") || t.is("slice")) notSupported(t);

  if (t.is("{")) return compoundStatement(true);

  if (t.is(";")) {
    advance();
    return newNode(NodeKind::Empty, pos);
  }

  if (t.kind == TokKind::Eof) fail(after(prevPos_), "expected statement at end of input");
  if (t.is("else")) fail(pos, "'else' without a previous 'if'");
  if (isDeclStart(t)) fail(pos, "declaration is not allowed here");
  return exprStatement();
}

// expr-stmt = expr ";"
Node* Parser::exprStatement() {
  Pos pos = cur().pos;
  Node* e = expr();
  Node* n = newNode(NodeKind::ExprStmt, pos);
  n->lhs = e;
  expectSemi("after expression");
  return n;
}

// compound-stmt = "{" (declaration | stmt)* "}"
Node* Parser::compoundStatement(bool newScope) {
  Node* n = newNode(NodeKind::Block, cur().pos);
  expect("{");
  if (newScope) enterScope();
  const char* dead = nullptr;  // the jump that ends every path to here
  bool warned = false;         // about this run of dead statements
  for (;;) {
    n->endPos = cur().pos;
    if (accept("}")) break;
    if (cur().kind == TokKind::Eof) diags_.fatal(after(prevPos_), "expected '}' at end of input");
    // A missing '}': what follows is the next function. Every open block
    // ends here and parsing resumes at file level.
    if (atFunctionDefinition()) {
      diags_.error(after(prevPos_),
                   "expected '}' before the definition of '" + functionNameAhead_ + "'");
      throw BackToFileLevel{};
    }
    Resume r = resumePoint();
    bool declaration = false;
    try {
      const Token& t = cur();
      if (isDeclStart(t) && !peek(1).is(":")) {
        declaration = true;
        localDeclaration(n->list);
        continue;
      }
      if (t.kind == TokKind::Ident && !isKeyword(t) && !findVar(t.text) &&
          (peek(1).kind == TokKind::Ident ||
           (peek(1).is("*") && peek(2).kind == TokKind::Ident && peek(3).is(";")))) {
        declaration = true;
        undeclared(t.pos, t.text, "unknown type name '" + t.text + "'");
      }
      Node* st = statement();
      n->list.push_back(st);
      // A label or case is reachable by a jump. Once per run of dead
      // statements; "return x; break;" in a switch is a harmless idiom.
      if (st->kind == NodeKind::Case || st->kind == NodeKind::Label) dead = nullptr;
      if (dead && !warned && st->kind != NodeKind::Empty && st->kind != NodeKind::Break) {
        diags_.warn(st->pos, "unreachable-code",
                    std::string("code after '") + dead + "' is never executed");
        warned = true;
      }
      if (const char* jump = endsPath(st)) {
        if (!dead) warned = false;
        dead = jump;
      }
    } catch (const CompileError& e) {
      recordError(e);
      skipStatement(r);
      if (declaration) poisonSince(r.token);
      scopes_.resize(r.scopes);
      switches_.resize(r.switches);
      loopDepth_ = r.loopDepth;
      breakDepth_ = r.breakDepth;
      // The error ate the rest of the file: "expected '}'" would only repeat it.
      if (cur().kind == TokKind::Eof) throw StopCompiling{};
    }
  }
  if (newScope) leaveScope();
  return n;
}

// ===================================================================
// Typing helpers.

Node* Parser::value(Node* e) {
  if (e->type->kind == TypeKind::Void) fail(e->pos, "void value not ignored as it ought to be");
  return e;
}

Node* Parser::num(int64_t v, Type* ty, Pos pos) {
  Node* n = newNode(NodeKind::Num, pos, ty);
  n->ival = wrapTo(v, ty);
  return n;
}

Node* Parser::fnum(double v, Pos pos) {
  Node* n = newNode(NodeKind::FNum, pos, tyFloat());
  n->fval = static_cast<float>(v);
  return n;
}

// Conversion of `e` to `to`, folded when `e` is a constant.
Node* Parser::castTo(Node* e, Type* to, Pos pos) {
  Type* from = e->type;
  if (from == to || (from->kind == to->kind && from->kind != TypeKind::Array &&
                     from->kind != TypeKind::Ptr && !isStructLike(from)))
    return e;
  if (to->kind != TypeKind::Void) {
    if (e->kind == NodeKind::Num && (isInteger(to) || to->kind == TypeKind::Ptr))
      return num(e->ival, to, e->pos);
    if (e->kind == NodeKind::Num && to->kind == TypeKind::Float)
      return fnum(static_cast<double>(e->ival), e->pos);
    if (e->kind == NodeKind::FNum && isInteger(to)) {
      double t = std::trunc(static_cast<double>(e->fval));
      int64_t v = (t > -9.0e18 && t < 9.0e18) ? static_cast<int64_t>(t) : 0;
      return num(v, to, e->pos);
    }
  }
  Node* n = newNode(NodeKind::Cast, pos, to);
  n->lhs = e;
  n->depth = e->depth + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

Node* Parser::binary(NodeKind k, Node* l, Node* r, Pos pos, Type* ty) {
  if (Node* f = fold(k, l, r, pos, ty)) return f;
  Node* n = newNode(k, pos, ty);
  n->lhs = l;
  n->rhs = r;
  n->depth = std::max(l->depth, r->depth) + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

// Constant folding, in the operands' (already converted) type.
Node* Parser::fold(NodeKind k, Node* l, Node* r, Pos pos, Type* ty) {
  if (!isConst(l) || !isConst(r)) return nullptr;
  if (k == NodeKind::LogAnd) return num(truthy(l) && truthy(r), tyInt(), pos);
  if (k == NodeKind::LogOr) return num(truthy(l) || truthy(r), tyInt(), pos);
  if (l->kind == NodeKind::FNum || r->kind == NodeKind::FNum) {
    if (l->kind != NodeKind::FNum || r->kind != NodeKind::FNum) return nullptr;
    float a = l->fval, b = r->fval;
    switch (k) {
      case NodeKind::Add:
        return fnum(static_cast<float>(a + b), pos);
      case NodeKind::Sub:
        return fnum(static_cast<float>(a - b), pos);
      case NodeKind::Mul:
        return fnum(static_cast<float>(a * b), pos);
      case NodeKind::Div:
        if (b == 0) fail(pos, "division by zero in constant expression");
        return fnum(static_cast<float>(a / b), pos);
      case NodeKind::Eq:
        return num(a == b, tyInt(), pos);
      case NodeKind::Ne:
        return num(a != b, tyInt(), pos);
      case NodeKind::Lt:
        return num(a < b, tyInt(), pos);
      case NodeKind::Le:
        return num(a <= b, tyInt(), pos);
      case NodeKind::Gt:
        return num(a > b, tyInt(), pos);
      case NodeKind::Ge:
        return num(a >= b, tyInt(), pos);
      default:
        return nullptr;
    }
  }
  int64_t a = l->ival, b = r->ival;
  bool isLong = l->type->size == 4;
  switch (k) {
    case NodeKind::Add:
      return num(a + b, ty, pos);
    case NodeKind::Sub:
      return num(a - b, ty, pos);
    case NodeKind::Mul:
      return num(static_cast<int64_t>(static_cast<uint64_t>(a) * static_cast<uint64_t>(b)), ty,
                 pos);
    case NodeKind::Div:
    case NodeKind::Mod:
      if (b == 0) fail(pos, "division by zero in constant expression");
      return num(k == NodeKind::Div ? a / b : a % b, ty, pos);
    case NodeKind::BitAnd:
      return num(a & b, ty, pos);
    case NodeKind::BitOr:
      return num(a | b, ty, pos);
    case NodeKind::BitXor:
      return num(a ^ b, ty, pos);
    case NodeKind::Shl:
      return num(static_cast<int64_t>(static_cast<uint64_t>(a) << (b & (isLong ? 31 : 15))), ty,
                 pos);
    case NodeKind::Shr:
      return num(a >> (b & (isLong ? 31 : 15)), ty, pos);
    case NodeKind::Eq:
      return num(a == b, tyInt(), pos);
    case NodeKind::Ne:
      return num(a != b, tyInt(), pos);
    case NodeKind::Lt:
      return num(a < b, tyInt(), pos);
    case NodeKind::Le:
      return num(a <= b, tyInt(), pos);
    case NodeKind::Gt:
      return num(a > b, tyInt(), pos);
    case NodeKind::Ge:
      return num(a >= b, tyInt(), pos);
    default:
      return nullptr;
  }
}

void Parser::badOperands(NodeKind k, Node* l, Node* r, Pos pos) {
  fail(pos, std::string("invalid operands to binary '") + opSpelling(k) + "' (" +
                typeCategory(l->type) + " and " + typeCategory(r->type) + ")");
}

// Arithmetic operators after the usual arithmetic conversions.
Node* Parser::arith(NodeKind k, Node* l, Node* r, Pos pos) {
  bool intOnly = k == NodeKind::Mod || k == NodeKind::BitAnd || k == NodeKind::BitOr ||
                 k == NodeKind::BitXor || k == NodeKind::Shl || k == NodeKind::Shr;
  if (!isArith(l->type) || !isArith(r->type) ||
      (intOnly && (!isInteger(l->type) || !isInteger(r->type))))
    badOperands(k, l, r, pos);
  if (k == NodeKind::Shl || k == NodeKind::Shr) {
    Type* t = promote(l->type);
    return binary(k, castTo(l, t, pos), castTo(r, tyInt(), pos), pos, t);
  }
  Type* t = commonType(l->type, r->type);
  return binary(k, castTo(l, t, pos), castTo(r, t, pos), pos, t);
}

// p + i, p - i: the index is scaled by the element size here.
Node* Parser::ptrOffset(NodeKind k, Node* p, Node* i, Pos pos) {
  Type* elem = p->type->base;
  if (elem->kind == TypeKind::Func || (isStructLike(elem) && !elem->complete))
    fail(pos, "arithmetic on a pointer to an incomplete type");
  int size = elem->kind == TypeKind::Void ? 1 : elem->size;
  Node* idx = castTo(i, tyInt(), pos);
  if (size != 1) idx = binary(NodeKind::Mul, idx, num(size, tyInt(), pos), pos, tyInt());
  Type* pt = p->type->kind == TypeKind::Ptr ? p->type : pointerTo(elem, pos);
  return binary(k, p, idx, pos, pt);
}

Node* Parser::newAdd(Node* l, Node* r, Pos pos) {
  value(l);
  value(r);
  if (isArith(l->type) && isArith(r->type)) return arith(NodeKind::Add, l, r, pos);
  if (isPtrLike(l->type) && isInteger(r->type)) return ptrOffset(NodeKind::Add, l, r, pos);
  if (isInteger(l->type) && isPtrLike(r->type)) return ptrOffset(NodeKind::Add, r, l, pos);
  badOperands(NodeKind::Add, l, r, pos);
}

Node* Parser::newSub(Node* l, Node* r, Pos pos) {
  value(l);
  value(r);
  if (isArith(l->type) && isArith(r->type)) return arith(NodeKind::Sub, l, r, pos);
  if (isPtrLike(l->type) && isInteger(r->type)) return ptrOffset(NodeKind::Sub, l, r, pos);
  if (isPtrLike(l->type) && isPtrLike(r->type)) {
    int ls = l->type->base->kind == TypeKind::Void ? 1 : l->type->base->size;
    int rs = r->type->base->kind == TypeKind::Void ? 1 : r->type->base->size;
    if (ls != rs) badOperands(NodeKind::Sub, l, r, pos);
    Node* diff =
        binary(NodeKind::Sub, castTo(l, tyInt(), pos), castTo(r, tyInt(), pos), pos, tyInt());
    if (ls > 1) diff = binary(NodeKind::Div, diff, num(ls, tyInt(), pos), pos, tyInt());
    return diff;
  }
  badOperands(NodeKind::Sub, l, r, pos);
}

// Comparisons leave int 0/1; pointers compare unsigned.
// "if (x = 5)": an assignment as a whole condition, unless parenthesised
// as gcc's -Wparentheses accepts ("if ((c = next()))").
void Parser::checkCondition(const Node* cond) {
  if ((cond->kind == NodeKind::Assign || cond->kind == NodeKind::OpAssign) && !cond->parenthesized)
    diags_.warn(cond->pos, "parentheses",
                "assignment used as a condition; write '==' to compare, or put the assignment "
                "in parentheses");
}

// A comparison of an integer expression with a constant outside the range
// of the expression's type (ICEMAN's idiom "int i; for(i=0;i<50000;i++);":
// 50000 is a long, the int wraps at 32767, the loop never ends). Decided in
// the type the comparison is done in, and only when converting the
// expression to it keeps every value (an int compared as unsigned does not).
void Parser::checkTypeLimits(NodeKind k, const Node* l, const Node* r, Pos pos) {
  const bool constLeft = l->kind == NodeKind::Num;
  const Node* e = constLeft ? r : l;
  const Node* c = constLeft ? l : r;
  if (c->kind != NodeKind::Num || e->kind == NodeKind::Num || !isInteger(e->type) ||
      !isInteger(c->type))
    return;
  const auto range = [](const Type* t) -> std::pair<int64_t, int64_t> {
    switch (t->kind) {
      case TypeKind::Char:
        return {0, 0xFF};
      case TypeKind::Int:
        return {-0x8000, 0x7FFF};
      case TypeKind::UInt:
        return {0, 0xFFFF};
      case TypeKind::Long:
        return {-0x80000000LL, 0x7FFFFFFF};
      default:
        return {0, 0xFFFFFFFFLL};
    }
  };
  Type* common = commonType(promote(e->type), promote(c->type));
  auto [lo, hi] = range(e->type);
  auto [clo, chi] = range(common);
  if (lo < clo || hi > chi) return;  // the conversion changes some values
  const int64_t v = wrapTo(c->ival, common);
  // x OP v with x in [lo, hi]; a constant on the left mirrors the operator.
  NodeKind op = k;
  if (constLeft) {
    if (k == NodeKind::Lt) op = NodeKind::Gt;
    if (k == NodeKind::Gt) op = NodeKind::Lt;
    if (k == NodeKind::Le) op = NodeKind::Ge;
    if (k == NodeKind::Ge) op = NodeKind::Le;
  }
  int verdict = -1;  // -1 depends on x, 0 always false, 1 always true
  switch (op) {
    case NodeKind::Lt:
      verdict = hi < v ? 1 : lo >= v ? 0 : -1;
      break;
    case NodeKind::Le:
      verdict = hi <= v ? 1 : lo > v ? 0 : -1;
      break;
    case NodeKind::Gt:
      verdict = lo > v ? 1 : hi <= v ? 0 : -1;
      break;
    case NodeKind::Ge:
      verdict = lo >= v ? 1 : hi < v ? 0 : -1;
      break;
    case NodeKind::Eq:
      verdict = v < lo || v > hi ? 0 : -1;
      break;
    case NodeKind::Ne:
      verdict = v < lo || v > hi ? 1 : -1;
      break;
    default:
      break;
  }
  if (verdict < 0) return;
  diags_.warn(pos, "tautological-compare",
              fmt::format("comparison is always {}: a value of type '{}' lies in {}..{}",
                          verdict ? "true" : "false", typeName(e->type), lo, hi));
}

Node* Parser::compare(NodeKind k, Node* l, Node* r, Pos pos) {
  value(l);
  value(r);
  if (isArith(l->type) && isArith(r->type)) {
    checkTypeLimits(k, l, r, pos);
    Type* t = commonType(l->type, r->type);
    return binary(k, castTo(l, t, pos), castTo(r, t, pos), pos, tyInt());
  }
  if ((isPtrLike(l->type) && (isPtrLike(r->type) || isInteger(r->type))) ||
      (isInteger(l->type) && isPtrLike(r->type))) {
    Type* pt = isPtrLike(l->type) ? l->type : r->type;
    if (pt->kind == TypeKind::Array) pt = pointerTo(pt->base, pos);
    return binary(k, castTo(l, pt, pos), castTo(r, pt, pos), pos, tyInt());
  }
  badOperands(k, l, r, pos);
}

Node* Parser::logical(NodeKind k, Node* l, Node* r, Pos pos) {
  value(l);
  value(r);
  if (!isScalar(l->type) || !isScalar(r->type)) badOperands(k, l, r, pos);
  return binary(k, l, r, pos, tyInt());
}

// The conversion as if by assignment (also arguments, returns, initialisers).
Node* Parser::assignConvert(Node* e, Type* ty, Pos pos, const std::string& context) {
  value(e);
  Type* from = e->type;
  if (isArith(ty) && isArith(from)) return castTo(e, ty, pos);
  if (ty->kind == TypeKind::Ptr && (isPtrLike(from) || isInteger(from))) {
    if (isInteger(from) && from->size == 4) e = castTo(e, tyUInt(), pos);
    return castTo(e, ty, pos);
  }
  if (isInteger(ty) && ty->size <= 2 && isPtrLike(from)) return castTo(e, ty, pos);
  if (isStructLike(ty) && from == ty) return e;
  std::string fromName =
      from->kind == TypeKind::Array ? typeName(from->base) + " *" : typeName(from);
  fail(pos, "incompatible types in " + context + " ('" + fromName + "' to '" + typeName(ty) + "')");
}

bool Parser::isLvalue(const Node* n) const {
  switch (n->kind) {
    case NodeKind::Var:
      return n->var->storage != Storage::Function;
    case NodeKind::Deref:
      return true;
    case NodeKind::Member:
      return isLvalue(n->lhs);
    default:
      return false;
  }
}

Node* Parser::newAssign(Node* l, Node* r, Pos pos) {
  if (!isLvalue(l) || l->type->kind == TypeKind::Array) fail(pos, "expression is not assignable");
  if (isStructLike(l->type) && !l->type->complete) fail(pos, "assignment to an incomplete type");
  Node* n = newNode(NodeKind::Assign, pos, l->type);
  n->lhs = l;
  n->rhs = assignConvert(r, l->type, pos, "assignment");
  n->depth = std::max(l->depth, n->rhs->depth) + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

Node* Parser::newOpAssign(NodeKind op, Node* l, Node* r, Pos pos) {
  if (!isLvalue(l) || l->type->kind == TypeKind::Array) fail(pos, "expression is not assignable");
  value(r);
  Node* n = newNode(NodeKind::OpAssign, pos, l->type);
  n->op = op;
  n->lhs = l;
  if ((op == NodeKind::Add || op == NodeKind::Sub) && l->type->kind == TypeKind::Ptr) {
    if (!isInteger(r->type)) badOperands(op, l, r, pos);
    Type* elem = l->type->base;
    int size = elem->kind == TypeKind::Void ? 1 : elem->size;
    Node* idx = castTo(r, tyInt(), pos);
    if (size != 1) idx = binary(NodeKind::Mul, idx, num(size, tyInt(), pos), pos, tyInt());
    n->rhs = idx;
    n->opType = l->type;
  } else {
    bool intOnly = op == NodeKind::Mod || op == NodeKind::BitAnd || op == NodeKind::BitOr ||
                   op == NodeKind::BitXor || op == NodeKind::Shl || op == NodeKind::Shr;
    if (!isArith(l->type) || !isArith(r->type) ||
        (intOnly && (!isInteger(l->type) || !isInteger(r->type))))
      badOperands(op, l, r, pos);
    if (op == NodeKind::Shl || op == NodeKind::Shr) {
      n->opType = promote(l->type);
      n->rhs = castTo(r, tyInt(), pos);
    } else {
      n->opType = commonType(l->type, r->type);
      n->rhs = castTo(r, n->opType, pos);
    }
  }
  n->depth = std::max(l->depth, n->rhs->depth) + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

Node* Parser::newIncDec(Node* e, int delta, bool prefix, Pos pos) {
  if (!isLvalue(e) || !isScalar(e->type) || e->type->kind == TypeKind::Array)
    fail(pos, "expression is not assignable");
  Node* n = newNode(NodeKind::IncDec, pos, e->type);
  n->lhs = e;
  n->prefix = prefix;
  if (e->type->kind == TypeKind::Ptr) {
    Type* elem = e->type->base;
    if (isStructLike(elem) && !elem->complete)
      fail(pos, "arithmetic on a pointer to an incomplete type");
    delta *= elem->kind == TypeKind::Void ? 1 : elem->size;
  }
  n->delta = delta;
  n->depth = e->depth + 1;
  return n;
}

Node* Parser::newDeref(Node* e, Pos pos) {
  value(e);
  if (!isPtrLike(e->type))
    fail(pos, "cannot dereference a non-pointer ('" + typeName(e->type) + "')");
  Type* base = e->type->base;
  if (base->kind == TypeKind::Void) fail(pos, "dereferencing a 'void *' pointer");
  Node* n = newNode(NodeKind::Deref, pos, base);
  n->lhs = e;
  n->depth = e->depth + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

Node* Parser::newAddr(Node* e, Pos pos) {
  if (e->kind == NodeKind::Var && e->var->isRegister)
    fail(pos, "cannot take the address of a register variable '" + e->var->name + "'");
  if (!isLvalue(e) && e->kind != NodeKind::Str) fail(pos, "cannot take the address of an rvalue");
  Node* n = newNode(NodeKind::Addr, pos, pointerTo(e->type, pos));
  n->lhs = e;
  n->depth = e->depth + 1;
  return n;
}

Node* Parser::member(Node* base, const Token& name, Pos pos) {
  Type* t = base->type;
  if (!isStructLike(t))
    fail(pos, "member reference base type '" + typeName(t) + "' is not a struct or union");
  if (!t->complete) fail(pos, "incomplete definition of type '" + typeName(t) + "'");
  if (name.kind != TokKind::Ident) fail(name.pos, "expected member name");
  for (const Member& m : t->members) {
    if (m.name == name.text) {
      Node* n = newNode(NodeKind::Member, name.pos, m.type);
      n->lhs = base;
      n->offset = m.offset;
      n->str = m.name;
      n->depth = base->depth + 1;
      return n;
    }
  }
  fail(name.pos, "no member named '" + name.text + "' in '" + typeName(t) + "'");
}

// ===================================================================
// Expressions.

// expr = assign ("," assign)*
Node* Parser::expr() {
  Node* n = assign();
  while (is(",")) {
    Pos pos = cur().pos;
    advance();
    Node* r = assign();
    Node* c = newNode(NodeKind::Comma, pos, r->type);
    c->lhs = n;
    c->rhs = r;
    c->depth = std::max(n->depth, r->depth) + 1;
    if (c->depth > kMaxTreeDepth) fail(pos, "expression too complex");
    n = c;
  }
  return n;
}

// assign = conditional (assign-op assign)?
// assign-op = "=" | "+=" | "-=" | "*=" | "/=" | "%=" | "&=" | "|=" | "^=" | "<<=" | ">>="
Node* Parser::assign() {
  Node* l = conditional();
  const Token& t = cur();
  if (t.kind != TokKind::Punct) return l;
  Pos pos = t.pos;
  static const std::pair<std::string_view, NodeKind> ops[] = {
      {"+=", NodeKind::Add},   {"-=", NodeKind::Sub},    {"*=", NodeKind::Mul},
      {"/=", NodeKind::Div},   {"%=", NodeKind::Mod},    {"&=", NodeKind::BitAnd},
      {"|=", NodeKind::BitOr}, {"^=", NodeKind::BitXor}, {"<<=", NodeKind::Shl},
      {">>=", NodeKind::Shr}};
  if (t.text == "=") {
    advance();
    DepthGuard guard(*this);
    return newAssign(l, assign(), pos);
  }
  for (auto [s, k] : ops) {
    if (t.text == s) {
      advance();
      DepthGuard guard(*this);
      return newOpAssign(k, l, assign(), pos);
    }
  }
  return l;
}

// The binary operators, loosest first; all associate to the left. The
// grammar this table stands for, one rule per level:
//   log-or         = log-and ("||" log-and)*
//   log-and        = bit-or ("&&" bit-or)*
//   bit-or         = bit-xor ("|" bit-xor)*
//   bit-xor        = bit-and ("^" bit-and)*
//   bit-and        = equality ("&" equality)*
//   equality       = relational (("==" | "!=") relational)*
//   relational     = shift (("<" | "<=" | ">" | ">=") shift)*
//   shift          = additive (("<<" | ">>") additive)*
//   additive       = multiplicative (("+" | "-") multiplicative)*
//   multiplicative = cast (("*" | "/" | "%") cast)*
struct BinaryOperator {
  std::string_view spelling;
  NodeKind kind;
  int precedence;  // 1 binds loosest
};
constexpr BinaryOperator kBinaryOperators[] = {
    {"||", NodeKind::LogOr, 1}, {"&&", NodeKind::LogAnd, 2}, {"|", NodeKind::BitOr, 3},
    {"^", NodeKind::BitXor, 4}, {"&", NodeKind::BitAnd, 5},  {"==", NodeKind::Eq, 6},
    {"!=", NodeKind::Ne, 6},    {"<", NodeKind::Lt, 7},      {"<=", NodeKind::Le, 7},
    {">", NodeKind::Gt, 7},     {">=", NodeKind::Ge, 7},     {"<<", NodeKind::Shl, 8},
    {">>", NodeKind::Shr, 8},   {"+", NodeKind::Add, 9},     {"-", NodeKind::Sub, 9},
    {"*", NodeKind::Mul, 10},   {"/", NodeKind::Div, 10},    {"%", NodeKind::Mod, 10}};
constexpr int kLoosestBinary = 1;

// conditional = binary ("?" expr ":" conditional)?
Node* Parser::conditional() {
  Node* c = binaryExpr(kLoosestBinary);
  if (!is("?")) return c;
  Pos pos = cur().pos;
  advance();
  DepthGuard guard(*this);
  value(c);
  if (!isScalar(c->type)) fail(c->pos, "condition must have scalar type");
  checkCondition(c);
  Node* a = expr();
  expect(":");
  Node* b = conditional();
  Type* t;
  if (isArith(a->type) && isArith(b->type)) {
    t = commonType(a->type, b->type);
    a = castTo(a, t, pos);
    b = castTo(b, t, pos);
  } else if (isPtrLike(a->type) && (isPtrLike(b->type) || b->kind == NodeKind::Num)) {
    t = a->type->kind == TypeKind::Array ? pointerTo(a->type->base, pos) : a->type;
    a = castTo(a, t, pos);
    b = castTo(b, t, pos);
  } else if (isPtrLike(b->type) && a->kind == NodeKind::Num) {
    t = b->type->kind == TypeKind::Array ? pointerTo(b->type->base, pos) : b->type;
    a = castTo(a, t, pos);
    b = castTo(b, t, pos);
  } else if (a->type->kind == TypeKind::Void && b->type->kind == TypeKind::Void) {
    t = tyVoid();
  } else if (isStructLike(a->type) && a->type == b->type) {
    t = a->type;
  } else {
    fail(pos, "type mismatch in conditional expression ('" + typeName(a->type) + "' and '" +
                  typeName(b->type) + "')");
  }
  if (isConst(c)) return truthy(c) ? a : b;
  Node* n = newNode(NodeKind::Cond, pos, t);
  n->cond = c;
  n->lhs = a;
  n->rhs = b;
  n->depth = std::max({c->depth, a->depth, b->depth}) + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

// binary = cast (binary-operator cast)*, grouped by the table's precedences
// (precedence climbing): the operands of an operator of precedence p bind
// tighter than p.
Node* Parser::binaryExpr(int minPrecedence) {
  Node* n = cast();
  for (;;) {
    const BinaryOperator* op = nullptr;
    if (cur().kind == TokKind::Punct)
      for (const BinaryOperator& o : kBinaryOperators)
        if (cur().text == o.spelling) op = &o;
    if (!op || op->precedence < minPrecedence) return n;
    const Pos pos = cur().pos;
    advance();
    Node* r = binaryExpr(op->precedence + 1);
    switch (op->kind) {
      case NodeKind::LogOr:
      case NodeKind::LogAnd:
        n = logical(op->kind, n, r, pos);
        break;
      case NodeKind::Eq:
      case NodeKind::Ne:
      case NodeKind::Lt:
      case NodeKind::Le:
      case NodeKind::Gt:
      case NodeKind::Ge:
        n = compare(op->kind, n, r, pos);
        break;
      case NodeKind::Add:
        n = newAdd(n, r, pos);
        break;
      case NodeKind::Sub:
        n = newSub(n, r, pos);
        break;
      default:  // | ^ & << >> * / %
        n = arith(op->kind, value(n), value(r), pos);
        break;
    }
  }
}

// cast = "(" type-name ")" cast | unary
Node* Parser::cast() {
  if (is("(") && isDeclStart(peek(1))) {
    DepthGuard guard(*this);
    Pos pos = cur().pos;
    advance();
    Type* t = abstractTypeName();
    expect(")");
    if (is("{")) fail(cur().pos, "compound literals are not supported");
    Node* e = cast();
    if (t->kind == TypeKind::Void) {
      Node* n = newNode(NodeKind::Cast, pos, tyVoid());
      n->lhs = e;
      n->depth = e->depth + 1;
      return n;
    }
    value(e);
    if (!isScalar(t)) fail(pos, "cannot cast to '" + typeName(t) + "'");
    if (!isScalar(e->type))
      fail(pos, "cannot cast '" + typeName(e->type) + "' to '" + typeName(t) + "'");
    if ((t->kind == TypeKind::Float && isPtrLike(e->type)) ||
        (isPtrLike(t) && e->type->kind == TypeKind::Float))
      fail(pos, "cannot cast between a pointer and a float");
    if (t->kind == TypeKind::Array) fail(pos, "cannot cast to an array type");
    if (t->kind == TypeKind::Ptr && isInteger(e->type) && e->type->size == 4)
      e = castTo(e, tyUInt(), pos);
    Node* c = castTo(e, t, pos);
    if (c == e && e->type != t) {  // same kind, different pointer type: retype
      c = newNode(NodeKind::Cast, pos, t);
      c->lhs = e;
      c->depth = e->depth + 1;
    }
    return c;
  }
  return unary();
}

// unary = ("+" | "-" | "!" | "~" | "*" | "&") cast
//       | ("++" | "--") unary
//       | "sizeof" "(" type-name ")" | "sizeof" unary
//       | postfix
Node* Parser::unary() {
  const Token& t = cur();
  Pos pos = t.pos;
  static const std::unordered_set<std::string_view> prefixOps = {"+", "-",  "!",  "~",     "*",
                                                                 "&", "++", "--", "sizeof"};
  if (!(t.kind == TokKind::Punct || t.kind == TokKind::Ident) || !prefixOps.count(t.text))
    return postfix();
  DepthGuard guard(*this);
  if (accept("+")) {
    Node* e = value(cast());
    if (!isArith(e->type))
      fail(pos, "invalid argument type '" + typeName(e->type) + "' to unary '+'");
    return castTo(e, promote(e->type), pos);
  }
  if (accept("-")) {
    Node* e = value(cast());
    if (!isArith(e->type))
      fail(pos, "invalid argument type '" + typeName(e->type) + "' to unary '-'");
    Type* ty = promote(e->type);
    e = castTo(e, ty, pos);
    if (e->kind == NodeKind::Num) return num(-e->ival, ty, pos);
    if (e->kind == NodeKind::FNum) return fnum(-e->fval, pos);
    Node* n = newNode(NodeKind::Neg, pos, ty);
    n->lhs = e;
    n->depth = e->depth + 1;
    return n;
  }
  if (accept("!")) {
    Node* e = value(cast());
    if (!isScalar(e->type))
      fail(pos, "invalid argument type '" + typeName(e->type) + "' to unary '!'");
    if (isConst(e)) return num(!truthy(e), tyInt(), pos);
    Node* n = newNode(NodeKind::Not, pos, tyInt());
    n->lhs = e;
    n->depth = e->depth + 1;
    return n;
  }
  if (accept("~")) {
    Node* e = value(cast());
    if (!isInteger(e->type))
      fail(pos, "invalid argument type '" + typeName(e->type) + "' to unary '~'");
    Type* ty = promote(e->type);
    e = castTo(e, ty, pos);
    if (e->kind == NodeKind::Num) return num(~e->ival, ty, pos);
    Node* n = newNode(NodeKind::BitNot, pos, ty);
    n->lhs = e;
    n->depth = e->depth + 1;
    return n;
  }
  if (accept("*")) return newDeref(cast(), pos);
  if (accept("&")) {
    Node* e = cast();
    if (e->kind == NodeKind::Var && e->var->storage == Storage::Function)
      fail(pos, "function pointers are not supported");
    return newAddr(e, pos);
  }
  if (accept("++")) return newIncDec(unary(), 1, true, pos);
  if (accept("--")) return newIncDec(unary(), -1, true, pos);
  if (accept("sizeof")) {
    Type* ty;
    if (is("(") && isDeclStart(peek(1))) {
      advance();
      ty = abstractTypeName();
      expect(")");
    } else {
      ty = unary()->type;
    }
    if (ty->kind == TypeKind::Void || ty->kind == TypeKind::Func ||
        (isStructLike(ty) && !ty->complete) || (ty->kind == TypeKind::Array && ty->arrayLen < 0))
      fail(pos, "invalid application of 'sizeof' to an incomplete type '" + typeName(ty) + "'");
    return num(ty->size, tyUInt(), pos);
  }
  return postfix();
}

// postfix = primary ("[" expr "]" | "." ident | "->" ident | "++" | "--")*
Node* Parser::postfix() {
  Node* n = primary();
  for (;;) {
    const Token& t = cur();
    Pos pos = t.pos;
    if (t.is("[")) {
      DepthGuard guard(*this);
      advance();
      Node* idx = expr();
      expect("]");
      value(n);
      value(idx);
      if (!(isPtrLike(n->type) && isInteger(idx->type)) &&
          !(isInteger(n->type) && isPtrLike(idx->type)))
        fail(pos, isPtrLike(n->type) ? "array subscript is not an integer"
                                     : "subscripted value is not an array or pointer");
      n = newDeref(newAdd(n, idx, pos), pos);
    } else if (t.is(".")) {
      advance();
      Token name = cur();
      advance();
      n = member(n, name, pos);
    } else if (t.is("->")) {
      advance();
      Token name = cur();
      advance();
      if (!isPtrLike(n->type) || !isStructLike(n->type->base))
        fail(pos, "member reference type '" + typeName(n->type) + "' is not a pointer to a struct");
      n = member(newDeref(n, pos), name, pos);
    } else if (t.is("++")) {
      advance();
      n = newIncDec(n, 1, false, pos);
    } else if (t.is("--")) {
      advance();
      n = newIncDec(n, -1, false, pos);
    } else if (t.is("(")) {
      fail(pos, "called object is not a function");
    } else {
      return n;
    }
  }
}

// primary = "(" expr ")" | ident | ident "(" args ")" | number | char | string+
Node* Parser::primary() {
  const Token& t = cur();
  Pos pos = t.pos;
  switch (t.kind) {
    case TokKind::Punct:
      if (t.is("(")) {
        DepthGuard guard(*this);
        advance();
        Node* e = expr();
        expect(")");
        e->parenthesized = true;
        return e;
      }
      fail(pos, "expected expression");
    case TokKind::Eof:
      fail(after(prevPos_), "expected expression at end of input");
    case TokKind::Number: {
      NumberValue v = parseNumber(t);
      advance();
      if (v.isFloat) return fnum(v.fvalue, pos);
      uint64_t x = v.value;
      Type* ty;
      if (v.suffixU && v.suffixL)
        ty = tyULong();
      else if (v.suffixU)
        ty = x <= 0xFFFF ? tyUInt() : tyULong();
      else if (v.suffixL)
        ty = x <= 0x7FFFFFFF ? tyLong() : tyULong();
      else if (v.decimal)
        ty = x <= 0x7FFF ? tyInt() : x <= 0x7FFFFFFF ? tyLong() : tyULong();
      else
        ty = x <= 0x7FFF       ? tyInt()
             : x <= 0xFFFF     ? tyUInt()
             : x <= 0x7FFFFFFF ? tyLong()
                               : tyULong();
      return num(static_cast<int64_t>(x), ty, pos);
    }
    case TokKind::Char: {
      if (t.str.empty()) fail(pos, "empty character constant");
      if (t.str.size() > 1) fail(pos, "multi-character character constant");
      int v = static_cast<unsigned char>(t.str[0]);
      advance();
      return num(v, tyInt(), pos);
    }
    case TokKind::String: {
      std::string s;
      while (cur().kind == TokKind::String) {
        s += cur().str;
        advance();
      }
      if (s.size() >= 0xFFFF) fail(pos, "string literal is too long");
      Node* n = newNode(NodeKind::Str, pos, arrayOf(tyChar(), static_cast<int>(s.size()) + 1, pos));
      n->str = std::move(s);
      return n;
    }
    case TokKind::Ident:
      break;
    default:
      fail(pos, "expected expression");
  }
  if (t.is("wfd") || t.is("waitfordone")) notSupported(t);
  if (isKeyword(t)) {
    if (isDeclStart(t)) fail(pos, "unexpected type name '" + t.text + "'");
    fail(pos, "expected expression before '" + t.text + "'");
  }
  Token nameTok = t;
  advance();
  ScopeEntry* e = findVar(nameTok.text);
  if (e) {
    if (e->typeDef) fail(pos, "unexpected type name '" + nameTok.text + "'");
    if (e->isConst) return num(e->value, tyInt(), pos);
    Obj* o = e->var;
    if (o->storage == Storage::Function) {
      if (!is("("))
        fail(pos, "function '" + nameTok.text +
                      "' used as a value (function pointers are not supported)");
      return funcall(nameTok, o->fn);
    }
    Node* n = newNode(NodeKind::Var, pos, o->type);
    n->var = o;
    if (is("(")) fail(cur().pos, "called object '" + nameTok.text + "' is not a function");
    if (o->biosTimer) useTimer();
    return n;
  }
  if (is("(")) {
    if (nameTok.text == "EI" || nameTok.text == "DI") {
      advance();
      if (!is(")"))
        fail(cur().pos, "too many arguments to function '" + nameTok.text + "' (expected 0)");
      advance();
      Node* n = newNode(NodeKind::Intrinsic, pos, tyVoid());
      n->lib = nameTok.text == "EI" ? 0 : 1;
      return n;
    }
    for (int i = 0; i < vm::kLibCount; ++i)
      if (vm::kLibInfo[i].name == nameTok.text) return libcall(nameTok, i);
    // K&R: an undeclared function is "int f()".
    Declarator d;
    d.name = nameTok.text;
    d.pos = pos;
    d.hasName = true;
    d.type = newType(TypeKind::Func, 1);
    d.type->base = tyInt();
    Function* f = declareFunction(d, VarAttr{});
    f->implicit = true;
    if (!poisoned_.count(nameTok.text))
      diags_.warn(pos, "implicit-function-declaration",
                  "implicit declaration of function '" + nameTok.text + "' (taken as 'int " +
                      nameTok.text + "()'; declare it before this call)");
    return funcall(nameTok, f);
  }
  undeclared(pos, nameTok.text, "undeclared identifier '" + nameTok.text + "'");
}

// funcall = ident "(" (assign ("," assign)*)? ")"
Node* Parser::funcall(const Token& nameTok, Function* f) {
  Pos pos = nameTok.pos;
  if (f->isHandler) fail(pos, "cannot call interrupt function '" + f->name + "'");
  DepthGuard guard(*this);
  advance();  // "("
  Node* n = newNode(NodeKind::Call, pos, f->type->base);
  n->callee = f;
  if (!accept(")")) {
    for (;;) {
      n->argPos.push_back(cur().pos);
      n->list.push_back(assign());
      if (accept(")")) break;
      if (cur().kind == TokKind::Eof) fail(after(prevPos_), "expected ')' at end of input");
      expect(",");
    }
  }
  Type* ft = f->type;
  if (ft->hasProto) {
    checkCallAgainstDefinition(f, n, false);  // counts; arguments are converted below
  }
  for (size_t i = 0; i < n->list.size(); ++i) {
    Node* a = value(n->list[i]);
    if (ft->hasProto) {
      n->list[i] = assignConvert(a, ft->params[i].type, n->argPos[i],
                                 "argument " + std::to_string(i + 1) + " to '" + f->name + "'");
    } else {
      if (isStructLike(a->type)) fail(n->argPos[i], "passing a struct by value is not supported");
      if (a->type->kind == TypeKind::Array)
        a = castTo(a, pointerTo(a->type->base, n->argPos[i]), n->argPos[i]);
      n->list[i] = castTo(a, promote(a->type), n->argPos[i]);
    }
    n->depth = std::max(n->depth, n->list[i]->depth + 1);
  }
  if (!ft->hasProto) f->uncheckedCalls.push_back(n);
  if (!f->called) {
    f->called = true;
    f->firstCall = pos;
  }
  return n;
}

// libcall = builtin-name "(" (assign ("," assign)*)? ")"
// Arguments are converted to the routine's type letters (builtins.def).
Node* Parser::libcall(const Token& nameTok, int lib) {
  const vm::LibInfo& info = vm::kLibInfo[lib];
  Pos pos = nameTok.pos;
  DepthGuard guard(*this);
  advance();  // "("
  std::vector<Node*> args;
  std::vector<Pos> argPos;
  if (!accept(")")) {
    for (;;) {
      argPos.push_back(cur().pos);
      args.push_back(assign());
      if (accept(")")) break;
      if (cur().kind == TokKind::Eof) fail(after(prevPos_), "expected ')' at end of input");
      expect(",");
    }
  }
  std::string_view letters = info.args;
  bool variadic = !letters.empty() && letters.back() == '.';
  if (variadic) letters.remove_suffix(1);
  std::string name(info.name);
  // Dynamic C's firsttime functions take the enclosing costatement's CoData
  // as a hidden first argument.
  const bool firsttime = lib == static_cast<int>(vm::Lib::DELAYMS) ||
                         lib == static_cast<int>(vm::Lib::DELAYSEC) ||
                         lib == static_cast<int>(vm::Lib::DELAYTICKS);
  Node* hidden = nullptr;
  if (firsttime) {
    if (costates_.empty())
      fail(pos, "'" + name + "' is used inside a costatement, as in 'waitfor(" + name + "(...));'");
    Node* cd = newNode(NodeKind::Var, pos, coDataType_);
    cd->var = costates_.back()->var;
    hidden = newAddr(cd, pos);
    letters.remove_prefix(1);
    useTimer();
  }
  if (args.size() > letters.size() && !variadic)
    fail(pos, "too many arguments to function '" + name + "' (expected " +
                  std::to_string(letters.size()) + ", got " + std::to_string(args.size()) + ")");
  if (args.size() < letters.size())
    fail(pos, "too few arguments to function '" + name + "' (expected " +
                  std::string(variadic ? "at least " : "") + std::to_string(letters.size()) +
                  ", got " + std::to_string(args.size()) + ")");
  Node* n = newNode(NodeKind::LibCall, pos);
  n->lib = lib;
  if (hidden) {
    n->list.push_back(hidden);
    n->argPos.push_back(pos);
  }
  for (size_t i = 0; i < args.size(); ++i) {
    Node* a = value(args[i]);
    Pos ap = argPos[i];
    std::string what = "argument " + std::to_string(i + 1) + " to '" + name + "'";
    const char letter = i < letters.size() ? letters[i] : '.';
    auto bad = [&]() {
      fail(ap, "incompatible type for " + what + " ('" + typeName(a->type) + "')");
    };
    switch (letter) {
      case 'i':
        if (!isScalar(a->type)) bad();
        a = assignConvert(a, tyInt(), ap, what);
        break;
      case 'u':
        if (!isScalar(a->type)) bad();
        a = assignConvert(a, tyUInt(), ap, what);
        break;
      case 'c':
        if (!isArith(a->type)) bad();
        a = castTo(castTo(a, tyChar(), ap), tyInt(), ap);
        break;
      case 'l':
        if (!isArith(a->type)) bad();
        a = castTo(a, tyLong(), ap);
        break;
      case 'f':
        if (!isArith(a->type)) bad();
        a = castTo(a, tyFloat(), ap);
        break;
      case 'p':
        if (!(isPtrLike(a->type) || (isInteger(a->type) && a->type->size <= 2))) bad();
        if (a->type->kind == TypeKind::Array) a = castTo(a, pointerTo(a->type->base, ap), ap);
        break;
      default:  // variadic extras: promoted
        if (isStructLike(a->type)) bad();
        if (a->type->kind == TypeKind::Array) a = castTo(a, pointerTo(a->type->base, ap), ap);
        a = castTo(a, promote(a->type), ap);
        break;
    }
    n->list.push_back(a);
    n->argPos.push_back(ap);
    n->depth = std::max(n->depth, a->depth + 1);
  }
  switch (info.result) {
    case 'v':
      n->type = tyVoid();
      break;
    case 'i':
      n->type = tyInt();
      break;
    case 'u':
      n->type = tyUInt();
      break;
    case 'c':
      n->type = tyChar();
      break;
    case 'l':
      n->type = tyLong();
      break;
    case 'f':
      n->type = tyFloat();
      break;
    default:
      n->type = pointerTo(tyChar(), pos);
      break;
  }
  return n;
}

// ===================================================================
// Costatements (Dynamic C User's Manual, chapter 5).
//
// A costatement is a block that keeps its own resume point, in a CoData
// structure, across passes of the loop around it: control that reaches it
// resumes where it last gave way (a yield, or a waitfor whose expression
// was false) and leaves through its closing brace. Unnamed costatements are
// always_on; a named one is a CoData variable of that name (created, or an
// existing global CoData) that starts paused unless always_on or init_on.
// The firsttime Delay functions and the timer variables are in libcall()
// and useTimer(); the code is laid out in codegen.cpp (costate()).

// The names a costatement program uses without declaring them: the CoData
// type (User's Manual 5.4.1: CSState, lastlocADDR, lastlocCBR, ChkSum,
// firsttime, content, ChkSum2) and the BIOS timer's shared counters.
void Parser::predefineCostateNames() {
  Type* co = newType(TypeKind::Struct, vm::kCoDataSize);
  co->tag = "CoData";
  const std::pair<const char*, std::pair<Type*, int>> members[] = {
      {"CSState", {tyChar(), vm::kCoState}},         {"lastlocADDR", {tyUInt(), vm::kCoLastLoc}},
      {"lastlocCBR", {tyChar(), vm::kCoLastLocCbr}}, {"ChkSum", {tyChar(), vm::kCoChkSum}},
      {"firsttime", {tyChar(), vm::kCoFirstTime}},   {"content", {tyULong(), vm::kCoContent}},
      {"ChkSum2", {tyChar(), vm::kCoChkSum2}}};
  for (const auto& [name, m] : members) co->members.push_back(Member{name, m.first, m.second});
  coDataType_ = co;
  ScopeEntry type;
  type.typeDef = co;
  scopes_[0].vars["CoData"] = type;

  const char* names[] = {"TICK_TIMER", "MS_TIMER", "SEC_TIMER", "bios_ms_fraction"};
  for (int i = 0; i < 4; ++i) {
    Obj* o = newObj(names[i], i == 3 ? tyChar() : tyULong(), Pos{}, Storage::Global);
    o->biosTimer = true;
    o->init = newInit(o->type);  // the BIOS zeroes them at start-up
    o->init->expr = num(0, o->type, Pos{});
    timerObjs_[i] = o;
    if (i < 3) {
      ScopeEntry e;
      e.var = o;
      scopes_[0].vars[names[i]] = e;
    }
  }
}

// Dynamic C constructs simbot does not build: cofunctions (cofunc, scofunc,
// firsttime functions, wfd / waitfordone) and slice statements.
void Parser::notSupported(const Token& t) {
  if (t.is("slice")) fail(t.pos, "'slice' statements are not supported by simbot");
  if (t.is("wfd") || t.is("waitfordone"))
    fail(t.pos, "'" + t.text + "' (cofunctions) is not supported by simbot");
  fail(t.pos, "'" + t.text + "' functions (cofunctions) are not supported by simbot");
}

// The program uses the timer library: the BIOS's counters become data of
// the image (and the timer service runs, profile knob permitting).
void Parser::useTimer() {
  if (timerUsed_) return;
  timerUsed_ = true;
  for (Obj* o : timerObjs_) prog_.globals.push_back(o);
  prog_.timer = timerObjs_;
}

// The CoData a named costatement uses: an existing global CoData of that
// name, or a new one (file scope, so that CoBegin(&name) works anywhere
// after it).
Obj* Parser::coDataNamed(const Token& name, int initialState) {
  if (ScopeEntry* e = findVar(name.text)) {
    if (!e->var || e->var->type != coDataType_ ||
        (e->var->storage != Storage::Global && e->var->storage != Storage::Static))
      fail(name.pos, "'" + name.text + "' names something other than a static CoData");
    return e->var;
  }
  Obj* o = newObj(name.text, coDataType_, name.pos, Storage::Global);
  o->init = newInit(coDataType_);
  Init* state = newInit(tyChar());
  state->expr = num(initialState, tyChar(), name.pos);
  o->init->children.push_back(state);
  ScopeEntry e;
  e.var = o;
  scopes_[1].vars[name.text] = e;
  prog_.globals.push_back(o);
  return o;
}

// costate-stmt = "costate" (ident ("always_on" | "init_on")?)? compound-stmt
Node* Parser::costateStatement() {
  Pos pos = cur().pos;
  advance();  // "costate"
  Node* n = newNode(NodeKind::Costate, pos);
  if (cur().kind == TokKind::Ident && !isKeyword(cur())) {
    Token name = cur();
    advance();
    int state = vm::kCoStopped | vm::kCoInit;  // named, no state: paused
    n->ival = 0;
    if (accept("always_on")) {
      state = 0;
      n->ival = 1;
    } else if (accept("init_on")) {
      state = vm::kCoInit;
    }
    n->var = coDataNamed(name, state);
    n->str = name.text;
  } else {
    if (is("always_on") || is("init_on"))
      fail(cur().pos, "'" + cur().text + "' needs a costatement name before it");
    // Unnamed: always_on, its CoData a static of the function.
    n->ival = 1;
    n->str = fmt::format("costate@{}", pos.line);
    Obj* o = newObj(n->str, coDataType_, pos, Storage::Static);
    o->symName = fn_->name + "." + n->str;
    o->init = newInit(coDataType_);
    fn_->locals.push_back(o);
    n->var = o;
  }
  if (!is("{")) fail(cur().pos, "expected '{' after 'costate'");
  const int savedLoop = loopDepth_, savedBreak = breakDepth_;
  loopDepth_ = breakDepth_ = 0;
  costates_.push_back(n);
  n->then = compoundStatement(true);
  costates_.pop_back();
  loopDepth_ = savedLoop;
  breakDepth_ = savedBreak;
  return n;
}

// waitfor-stmt = "waitfor" "(" expr ")" ";"
Node* Parser::waitforStatement() {
  Pos pos = cur().pos;
  if (costates_.empty()) fail(pos, "'waitfor' outside a costatement");
  advance();
  Node* n = newNode(NodeKind::Waitfor, pos);
  n->costate = costates_.back();
  expect("(");
  n->cond = value(expr());
  if (!isScalar(n->cond->type)) fail(n->cond->pos, "condition must have scalar type");
  expect(")");
  expectSemi("after 'waitfor'");
  return n;
}

// yield-stmt = "yield" ";"
// abort-stmt = "abort" ";"
Node* Parser::costateControl(NodeKind kind) {
  Pos pos = cur().pos;
  const std::string word = cur().text;
  if (costates_.empty()) fail(pos, "'" + word + "' outside a costatement");
  advance();
  Node* n = newNode(kind, pos);
  n->costate = costates_.back();
  expectSemi("after '" + word + "'");
  return n;
}

// const-expr = conditional, which must fold to an integer constant
int64_t Parser::constExpr(Type** type) {
  Pos pos = cur().pos;
  Node* n = conditional();
  if (n->kind != NodeKind::Num) fail(pos, "expression is not an integer constant");
  if (type) *type = n->type;
  return n->ival;
}

}  // namespace

void parse(Preprocessor& pp, const Options& options, Program& prog, Diagnostics& diags) {
  Parser(pp, options, prog, diags).run();
}

}  // namespace simbot::compiler
