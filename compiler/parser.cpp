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
//
// This file: the token cursor, scopes and arenas, the run over a file and
// error recovery; the rules are in parse_decl.cpp, parse_stmt.cpp,
// parse_expr.cpp and types.cpp (parser_impl.h).
#include "compiler/parser_impl.h"

namespace simbot::compiler {

namespace detail {

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
  if (base->kind == TypeKind::Func && base->variadic)
    fail(base->ellipsisPos, "variadic functions are not supported");
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
    incomplete(pos, base, "array has incomplete element type '" + typeName(base) + "'");
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
// The run over a file.

// program = (";" | external-declaration)*
void Parser::run() {
  enterScope();  // predefined names, shadowable by the program
  for (auto [name, value] : {std::pair<const char*, int>{"PIODA", vm::kPortPIODA},
                             {"PIODB", vm::kPortPIODB},
                             {"PIOCA", vm::kPortPIOCA},
                             {"PIOCB", vm::kPortPIOCB},
                             {"ENB485", vm::kPortENB485},
                             {"PIOA_VEC", vm::kVecPIOA},
                             // C's null pointer constant, an integer 0 (a
                             // name, not a macro: a program's own #define
                             // NULL or #ifndef NULL still works).
                             {"NULL", 0}}) {
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

void Parser::incomplete(Pos pos, const Type* t, std::string message) {
  const bool followsAnError = isStructLike(t) && !t->tag.empty() && poisoned_.count(t->tag) > 0;
  throw CompileError{pos, std::move(message), followsAnError};
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

}  // namespace detail

void parse(Preprocessor& pp, const Options& options, Program& prog, Diagnostics& diags) {
  detail::Parser(pp, options, prog, diags).run();
}

}  // namespace simbot::compiler
