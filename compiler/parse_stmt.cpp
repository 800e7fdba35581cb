// compiler/parse_stmt.cpp -- the parser's statements (parser_impl.h),
// Dynamic C's costatements among them.
#include "compiler/parser_impl.h"

namespace simbot::compiler::detail {

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
    n->cond = parenCondition();
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
    if (!is(";")) n->cond = condition(expr());
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
    n->cond = parenCondition();
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
    n->cond = parenCondition();
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

// "(" expr ")" tested for truth: if, while, do-while and waitfor.
Node* Parser::parenCondition(bool warnAssignment) {
  expect("(");
  Node* c = condition(expr(), warnAssignment);
  expect(")");
  return c;
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
  // Dynamic C's waitfor has never warned about an assignment: the
  // expression is often a call with effects, "waitfor(c = getc())".
  n->cond = parenCondition(false);
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

}  // namespace simbot::compiler::detail
