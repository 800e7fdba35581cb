// compiler/parse_decl.cpp -- the parser's declarations (parser_impl.h):
// external declarations, declaration specifiers, declarators, function
// definitions, globals, locals and their initialisers.
#include "compiler/parser_impl.h"

namespace simbot::compiler::detail {

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
      if (!libraryDeclaration(d)) declareFunction(d, attr);
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
  using namespace typeword;
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
      counter += kOther;
      advance();
      continue;
    }
    if (w == "struct" || w == "union" || w == "enum") {
      if (counter) fail(pos, "invalid combination of type specifiers");
      advance();
      ty = w == "enum" ? enumSpecifier() : structDecl(w == "union");
      counter += kOther;
      continue;
    }
    if (w == "void")
      counter += kVoid;
    else if (w == "char")
      counter += kChar;
    else if (w == "short")
      counter += kShort;
    else if (w == "int")
      counter += kInt;
    else if (w == "long") {
      if (counter & kLong) fail(pos, "long long is not supported");
      counter += kLong;
    } else if (w == "float")
      counter += kFloat;
    else if (w == "double")
      counter += kDouble;
    else if (w == "signed")
      counter |= kSigned;
    else if (w == "unsigned")
      counter |= kUnsigned;

    if (counter == kVoid) {
      ty = tyVoid();
    } else if (const std::optional<Arith> a = typeWordsArith(counter)) {
      ty = arithType(*a);
    } else {
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
    const Pos memberPos = cur().pos;
    Type* base = declspec(&attr);
    if (attr.sawStorage || attr.isInterrupt) fail(cur().pos, "storage class in a struct member");
    // C89's grammar wants at least one member declarator; gcc and clang
    // take "int;" (or "struct U { ... };", which declares the tag U) with a
    // warning that it declares nothing, and so does simbot. C11's
    // anonymous struct or union member (which Dynamic C did not have)
    // would make its members the outer one's: refused, not dropped.
    if (is(";")) {
      if (isStructLike(base) && base->tag.empty() && at(i_ - 1).is("}"))
        fail(cur().pos, "anonymous struct or union members are not supported; name the member");
      diags_.warn(memberPos, "missing-member-name",
                  "member declaration declares nothing (no member name)");
      advance();
      continue;
    }
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
        incomplete(d.pos, d.type, "member '" + d.name + "' has incomplete type");
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
  if (startsNestedDeclarator()) {
    // "(*p)[3]", "(*(getf(void)))(int)", "(x)": the suffix after the ")"
    // applies first. It is parsed first, then the inner declarator once
    // with the type it makes (parsing the inner one twice, as this did,
    // took 2^depth passes: 26 levels of "(*" ran for minutes).
    const size_t start = i_;
    size_t close = start;
    for (int depth = 0;; ++close) {
      const Token& t = at(close);
      if (t.kind == TokKind::Eof) break;
      if (t.is("(")) ++depth;
      if (t.is(")") && --depth == 0) break;
    }
    if (at(close).kind != TokKind::Eof) {
      i_ = close + 1;
      prevPos_ = at(close).pos;
      settle();
      ty = typeSuffix(ty);
    }
    const size_t end = i_;
    const Pos endPrev = prevPos_;
    i_ = start;
    advance();
    declarator(ty, d);
    expect(")");
    if (at(close).kind != TokKind::Eof) {
      i_ = end;
      prevPos_ = endPrev;
    }
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

// A "(" where a declarator's name may stand opens a nested declarator when
// what follows can only begin one: "*", another "(" (redundant parentheses,
// "int ((*fp))(void)") or a name that is not a type ("int (x);"). Before a
// type name or ")" it is the parameter list of an abstract declarator
// ("int (*)(int)", "int ()").
bool Parser::startsNestedDeclarator() {
  if (!is("(")) return false;
  const Token& next = peek(1);
  if (next.is("*") || next.is("(")) return true;
  return next.kind == TokKind::Ident && !isKeyword(next) && !isDeclStart(next);
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
    if (is("...")) {
      if (fn->params.empty()) fail(cur().pos, "expected a named parameter before '...'");
      fn->variadic = true;
      fn->ellipsisPos = cur().pos;
      advance();
      expect(")");
      return fn;
    }
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
    if (t->kind == TypeKind::Func) t = pointerTo(t, d.pos);  // C89 3.7.1: adjusted
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
namespace {

// A type as one of builtins.def's type letters ('?': none fits).
char typeLetter(const Type* t) {
  switch (t->kind) {
    case TypeKind::Void:
      return 'v';
    case TypeKind::Char:
      return 'c';
    case TypeKind::Int:
      return 'i';
    case TypeKind::UInt:
      return 'u';
    case TypeKind::Long:
      return 'l';
    case TypeKind::Float:
      return 'f';
    case TypeKind::Ptr:
    case TypeKind::Array:
      return 'p';
    default:
      return '?';
  }
}

// int and unsigned are the same 16-bit word to a routine.
bool lettersAgree(char declared, char library) {
  const auto word = [](char c) { return c == 'i' || c == 'u'; };
  return declared == library || (word(declared) && word(library));
}

std::string letterName(char c) {
  switch (c) {
    case 'v':
      return "void";
    case 'c':
      return "char";
    case 'i':
      return "int";
    case 'u':
      return "unsigned";
    case 'l':
      return "long";
    case 'f':
      return "float";
    default:
      return "a pointer";
  }
}

}  // namespace

// A declaration of a library routine without a body: K&R's "char
// *strcpy();", or a prototype, "extern int printf(const char *, ...);". It
// declares nothing new (calls still reach the routine) when it agrees with
// the routine: the same result and, for a prototype, the same parameters
// (int and unsigned alike, any pointer for a pointer, "..." where the
// routine is variadic). Otherwise an error naming both. False if `d` names
// no library routine.
bool Parser::libraryDeclaration(const Declarator& d) {
  const int lib = library(d.name);
  if (lib < 0) return false;
  const vm::LibInfo* info = &vm::kLibInfo[lib];
  const Type* fn = d.type;
  std::string_view args = info->args;
  const bool variadic = !args.empty() && args.back() == '.';
  if (variadic) args.remove_suffix(1);
  bool agrees = lettersAgree(typeLetter(fn->base), info->result);
  if (fn->hasProto) {
    agrees = agrees && fn->params.size() == args.size() && fn->variadic == variadic;
    for (size_t k = 0; agrees && k < args.size(); ++k)
      agrees = lettersAgree(typeLetter(fn->params[k].type), args[k]);
  }
  if (!agrees) {
    std::string takes;
    for (size_t k = 0; k < args.size(); ++k) takes += (k ? ", " : "") + letterName(args[k]);
    if (variadic) takes += ", ...";
    fail(d.pos, "declaration of '" + d.name + "' does not agree with the library's " + d.name +
                    ": returns " + letterName(info->result) + ", takes (" + takes + ")");
  }
  return true;
}

Function* Parser::declareFunction(Declarator& d, const VarAttr& attr) {
  if (d.type->variadic) fail(d.type->ellipsisPos, "variadic functions are not supported");
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
    if (attr.isInterrupt) {
      f->isHandler = true;
      if (f->addressTaken)
        fail(f->addressPos, "cannot take the address of interrupt function '" + f->name +
                                "' (it returns with RETI; bind it to a vector with #INT_VEC)");
    }
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
        if (t->kind == TypeKind::Func) t = pointerTo(t, pd.pos);
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
    incomplete(obj->pos, t, "storage size of '" + obj->name + "' is not known");
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
      if (!libraryDeclaration(d)) declareFunction(d, attr);
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
    bool charArray = ty->base->kind == TypeKind::Char || ty->base->kind == TypeKind::SChar;
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
  if (!ty->complete)
    incomplete(cur().pos, ty, "initializing an incomplete type '" + typeName(ty) + "'");
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

}  // namespace simbot::compiler::detail
