// The warnings that need a whole function or the whole program, run on an
// error-free, type-checked Program before code generation:
//
// uninitialized: a local scalar variable that its function reads but never
//   assigns. Locals are static by default and memory is zero at power-on, so
//   a read before the first assignment in a loop is often deliberate (the
//   second pass sees the value of the first); the rule therefore looks for no
//   assignment at all, anywhere in the function, which has no false
//   positives: such a variable reads 0 only because of the power-on state
//   (or garbage under #class auto, or with the memory-fill profile option).
//   An assignment, an initialiser, ++/--, a compound assignment or taking
//   the address counts as assigning. Arrays, structs and parameters are not
//   checked.
//   A global scalar or pointer (file-level static too) is checked over the
//   whole program: read somewhere, and never assigned in any function
//   (interrupt handlers included) nor by an initialiser, and its address
//   never taken anywhere (in code or in another global's initialiser: a
//   write through a pointer, or by a library routine such as ser_send_z1's
//   &cc or memset(&x, ...), then counts). The BIOS's timer variables are
//   written by the BIOS and not checked.
//
// send-without-delay: a ser_send_z1 that can run after an earlier one with
//   no delay between them. The Z180's serial port sends the motor command
//   from the buffer while the program goes on; a second send before the
//   first has gone out overwrites it (ICEMAN's platform() ends with a
//   700-iteration loop for that reason). Along every path of a function (a
//   may-analysis over the syntax tree, loops to a fixed point), a send sets
//   "pending"; a delay clears it. A delay is any loop whose condition, body
//   and step contain no send (directly or through a call), or a call to a
//   function that delays on every path through it after its last send. A
//   call to a function that can send before it delays, while pending, is
//   reported at the call; calls are summarised (can it send before a delay,
//   can it return pending, can it return without sending or delaying), so
//   "platform(); platform();" is caught where it is written. Sends reached
//   only through goto labels are not followed.
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <set>
#include <vector>

#include "compiler/ast.h"
#include "vm/bytecode.h"

namespace simbot::compiler {

namespace {

// ---- uninitialized ----

void collectUses(const Node* n, std::set<const Obj*>& written, std::map<const Obj*, Pos>& reads);

void collectInit(const Init* init, std::set<const Obj*>& written,
                 std::map<const Obj*, Pos>& reads) {
  if (!init) return;
  collectUses(init->expr, written, reads);
  for (const Init* c : init->children) collectInit(c, written, reads);
}

void collectUses(const Node* n, std::set<const Obj*>& written, std::map<const Obj*, Pos>& reads) {
  if (!n) return;
  const auto target = [&](const Node* lhs) {
    if (lhs && lhs->kind == NodeKind::Var) {
      written.insert(lhs->var);
      return true;
    }
    return false;
  };
  switch (n->kind) {
    case NodeKind::Var:
      if (!reads.count(n->var)) reads[n->var] = n->pos;
      return;
    case NodeKind::Assign:
      if (!target(n->lhs)) collectUses(n->lhs, written, reads);
      collectUses(n->rhs, written, reads);
      return;
    case NodeKind::OpAssign:
    case NodeKind::IncDec:
    case NodeKind::Addr:
      if (!target(n->lhs)) collectUses(n->lhs, written, reads);
      collectUses(n->rhs, written, reads);
      return;
    case NodeKind::DeclInit:
      written.insert(n->var);
      collectInit(n->initv, written, reads);
      return;
    default:
      break;
  }
  for (const Node* c : {n->lhs, n->rhs, n->cond, n->then, n->els, n->init, n->inc})
    collectUses(c, written, reads);
  for (const Node* c : n->list) collectUses(c, written, reads);
}

void uninitialized(const Function& f, Diagnostics& diags) {
  std::set<const Obj*> written;
  std::map<const Obj*, Pos> reads;
  collectUses(f.body, written, reads);
  for (const Obj* o : f.locals) {
    if (o->isParam || o->init || !(isArith(o->type) || o->type->kind == TypeKind::Ptr)) continue;
    auto r = reads.find(o);
    if (r == reads.end() || written.count(o)) continue;
    diags.warn(r->second, "uninitialized",
               o->storage == Storage::Auto
                   ? fmt::format("'{}' is read but never assigned in '{}': an auto variable "
                                 "holds whatever its stack slot held",
                                 o->name, f.name)
                   : fmt::format("'{}' is read but never assigned in '{}': it holds 0 only "
                                 "because memory is zero at power-on",
                                 o->name, f.name));
  }
}

// Globals read somewhere in the program and assigned nowhere (above).
void uninitializedGlobals(const Program& prog, Diagnostics& diags) {
  std::set<const Obj*> written;
  std::map<const Obj*, Pos> reads;
  for (const Obj* o : prog.globals) collectInit(o->init, written, reads);
  for (const Function* f : prog.functions) {
    for (const Obj* o : f->locals) collectInit(o->init, written, reads);
    collectUses(f->body, written, reads);
  }
  // Each is reported at the first read met (functions in definition order).
  for (const Obj* o : prog.globals) {
    if (o->init || o->isExtern || o->biosTimer || o->storage == Storage::Function) continue;
    if (!o->type || !(isArith(o->type) || o->type->kind == TypeKind::Ptr)) continue;
    if (std::find(prog.timer.begin(), prog.timer.end(), o) != prog.timer.end()) continue;
    if (written.count(o)) continue;
    const auto r = reads.find(o);
    if (r == reads.end()) continue;
    diags.warn(r->second, "uninitialized",
               fmt::format("global '{}' is read but never assigned anywhere in the program: it "
                           "holds 0 only because memory is zero at power-on (not with the "
                           "profile's random_memory); initialise it, or assign it before use",
                           o->name));
  }
}

// ---- send-without-delay ----

// Pending bits: a send of this function, or one of its caller (made before
// the call, "entry"), with no delay since.
constexpr unsigned kMine = 1, kEntry = 2;

struct Summary {
  bool sends = false;        // may send (itself or through calls)
  bool entrySend = false;    // may send before any delay, from its entry
  bool exitPending = false;  // may return with a send of its own pending
  bool passThrough = false;  // may return having neither sent nor delayed
  bool operator==(const Summary& o) const {
    return sends == o.sends && entrySend == o.entrySend && exitPending == o.exitPending &&
           passThrough == o.passThrough;
  }
};

bool isSend(const Node* n) {
  return n->kind == NodeKind::LibCall && n->lib == static_cast<int>(vm::Lib::SER_SEND_Z1);
}

class SendFlow {
 public:
  SendFlow(const std::map<const Function*, Summary>& sums, bool report, Diagnostics& diags)
      : sums_(sums), report_(report), diags_(diags) {}

  Summary run(const Function& f) {
    summary_ = Summary{};
    summary_.sends = containsSend(f.body);
    returns_ = 0;
    unsigned end = stmt(f.body, kEntry) | returns_;
    summary_.exitPending = end & kMine;
    summary_.passThrough = end & kEntry;
    return summary_;
  }

  bool containsSend(const Node* n) const {
    if (!n) return false;
    if (isSend(n)) return true;
    if (n->kind == NodeKind::Call) {
      auto s = sums_.find(n->callee);
      if (s != sums_.end() && s->second.sends) return true;
    }
    for (const Node* c : {n->lhs, n->rhs, n->cond, n->then, n->els, n->init, n->inc})
      if (containsSend(c)) return true;
    for (const Node* c : n->list)
      if (containsSend(c)) return true;
    return false;
  }

 private:
  void warn(const Node* n, std::string message) {
    if (report_ && warned_.insert(n).second)
      diags_.warn(n->pos, "send-without-delay", std::move(message));
  }

  // A send (or a call that can send first) reached in state s.
  void sendAt(const Node* n, unsigned s, const char* who) {
    if (s & kEntry) summary_.entrySend = true;
    if (s & kMine)
      warn(n, fmt::format("{} can follow an earlier send with no delay loop between them; the "
                          "earlier motor command may still be going out and is overwritten",
                          who));
  }

  unsigned expr(const Node* n, unsigned s) {
    if (!n) return s;
    switch (n->kind) {
      case NodeKind::LogAnd:
      case NodeKind::LogOr: {
        unsigned a = expr(n->lhs, s);
        return a | expr(n->rhs, a);
      }
      case NodeKind::Cond: {
        unsigned c = expr(n->cond, s);
        return expr(n->lhs, c) | expr(n->rhs, c);
      }
      default:
        break;
    }
    for (const Node* c : {n->lhs, n->rhs, n->cond, n->init, n->inc}) s = expr(c, s);
    for (const Node* c : n->list) s = expr(c, s);
    if (isSend(n)) {
      sendAt(n, s, "'ser_send_z1'");
      return kMine;
    }
    if (n->kind == NodeKind::Call) {
      auto it = sums_.find(n->callee);
      if (it == sums_.end()) return s;
      const Summary& g = it->second;
      if (g.entrySend) {
        const std::string who = "the send in '" + n->callee->name + "'";
        sendAt(n, s, who.c_str());
      }
      return (g.exitPending ? kMine : 0) | (g.passThrough ? s : 0);
    }
    return s;
  }

  // A loop from state s: its head state to a fixed point (two bits, so a
  // few rounds), the exits joined.
  unsigned loop(const Node* n, unsigned s) {
    if (!containsSend(n)) return 0;  // a delay loop
    const bool forever = !n->cond || (n->cond->kind == NodeKind::Num && n->cond->ival != 0);
    breaks_.push_back(0);
    continues_.push_back(0);
    unsigned head = n->kind == NodeKind::For ? expr(n->init, s) : s;
    unsigned out = 0;
    for (;;) {
      continues_.back() = 0;
      unsigned next;
      if (n->kind == NodeKind::DoWhile) {
        unsigned b = stmt(n->then, head) | continues_.back();
        unsigned c = expr(n->cond, b);
        out = forever ? 0 : c;
        next = head | c;
      } else {
        unsigned c = expr(n->cond, head);
        unsigned b = stmt(n->then, c) | continues_.back();
        out = forever ? 0 : c;
        next = head | expr(n->inc, b);
      }
      if (next == head) break;
      head = next;
    }
    out |= breaks_.back();
    breaks_.pop_back();
    continues_.pop_back();
    return out;
  }

  unsigned stmt(const Node* n, unsigned s) {
    if (!n) return s;
    switch (n->kind) {
      case NodeKind::Block:
        for (const Node* c : n->list) s = stmt(c, s);
        return s;
      case NodeKind::ExprStmt:
        return expr(n->lhs, s);
      case NodeKind::DeclInit:
        return initExpr(n->initv, s);
      case NodeKind::If: {
        unsigned c = expr(n->cond, s);
        return stmt(n->then, c) | (n->els ? stmt(n->els, c) : c);
      }
      case NodeKind::While:
      case NodeKind::DoWhile:
      case NodeKind::For:
        return loop(n, s);
      case NodeKind::Switch: {
        unsigned c = expr(n->cond, s);
        bool hasDefault = false;
        for (const Node* k : n->cases) hasDefault = hasDefault || k->isDefault;
        switches_.push_back(c);
        breaks_.push_back(0);
        unsigned end = stmt(n->then, 0);
        unsigned out = end | breaks_.back() | (hasDefault ? 0 : c);
        breaks_.pop_back();
        switches_.pop_back();
        return out;
      }
      case NodeKind::Case:
        return stmt(n->then, s | (switches_.empty() ? 0 : switches_.back()));
      case NodeKind::Label:
        return stmt(n->then, s);
      case NodeKind::Return:
        returns_ |= expr(n->lhs, s);
        return 0;
      case NodeKind::Break:
        if (!breaks_.empty()) breaks_.back() |= s;
        return 0;
      case NodeKind::Continue:
        if (!continues_.empty()) continues_.back() |= s;
        return 0;
      case NodeKind::Goto:
        return 0;
      default:
        return s;
    }
  }

  unsigned initExpr(const Init* init, unsigned s) {
    if (!init) return s;
    s = expr(init->expr, s);
    for (const Init* c : init->children) s = initExpr(c, s);
    return s;
  }

  const std::map<const Function*, Summary>& sums_;
  bool report_;
  Diagnostics& diags_;
  Summary summary_;
  unsigned returns_ = 0;
  std::vector<unsigned> breaks_, continues_, switches_;
  std::set<const Node*> warned_;
};

void sendWithoutDelay(const Program& prog, Diagnostics& diags) {
  // Summaries only grow (every flag starts false and the flow is monotone),
  // so rounds until nothing changes end; then one round reports.
  std::map<const Function*, Summary> sums;
  for (const Function* f : prog.functions) sums[f] = Summary{};
  for (bool changed = true; changed;) {
    changed = false;
    for (const Function* f : prog.functions) {
      SendFlow flow(sums, false, diags);
      Summary s = flow.run(*f);
      if (!(s == sums[f])) {
        sums[f] = s;
        changed = true;
      }
    }
  }
  for (const Function* f : prog.functions) SendFlow(sums, true, diags).run(*f);
}

}  // namespace

void analyze(const Program& prog, Diagnostics& diags) {
  for (const Function* f : prog.functions) uninitialized(*f, diags);
  uninitializedGlobals(prog, diags);
  sendWithoutDelay(prog, diags);
}

}  // namespace simbot::compiler
