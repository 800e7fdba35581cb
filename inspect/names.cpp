// inspect/names.cpp -- what the names in an expression mean (names.h):
// the scope a stopped robot's frame gives, C's lookup from it, and the
// variables it can see (DAP's scopes).
#include "inspect/names.h"

#include <fmt/format.h>

#include <algorithm>

#include "inspect/types.h"

namespace simbot::inspect {

using vm::Symbol;

Scope::Scope(const vm::Vm& v, int selected)
    : vm(&v), activations(v.activations()), image_(&v.image()) {
  frame = std::clamp(selected, 0, std::max(0, static_cast<int>(activations.size()) - 1));
}

Scope::Scope(const vm::Image& image) : image_(&image) {}

const Symbol* Scope::function() const {
  if (activations.empty()) return nullptr;
  return image().functionAt(activations[static_cast<size_t>(frame)].pc);
}

int Scope::line() const {
  if (activations.empty()) return 0;
  return image().lineAt(activations[static_cast<size_t>(frame)].pc);
}

Found lookUp(const Scope& s, const std::string& function, const std::string& name) {
  const vm::Image& img = s.image();
  auto local = [&](const std::string& fn, int frame, int line) -> Found {
    const std::string qualified = fn + "." + name;
    const Symbol* best = nullptr;
    for (const Symbol& sym : img.symbols) {
      if (sym.name != qualified) continue;
      // Statics and a static function's parameters have addresses.
      if (sym.kind == Symbol::Kind::Static || sym.kind == Symbol::Kind::Param) {
        if (!best) best = &sym;
        continue;
      }
      if (sym.kind != Symbol::Kind::Auto || frame < 0) continue;
      const bool inScope =
          sym.parameter || (line >= sym.line && (sym.scopeEnd == 0 || line <= sym.scopeEnd));
      if (inScope && (!best || best->kind != Symbol::Kind::Auto || sym.line > best->line))
        best = &sym;
    }
    return best ? Found{best, best->kind == Symbol::Kind::Auto ? frame : -1} : Found{};
  };
  if (!function.empty()) {
    // The innermost activation of that function holds its autos.
    for (size_t f = 0; f < s.activations.size(); ++f) {
      const Symbol* fn = img.functionAt(s.activations[f].pc);
      if (fn && fn->name == function) {
        const Found found = local(function, static_cast<int>(f), img.lineAt(s.activations[f].pc));
        if (found.symbol) return found;
      }
    }
    const Found found = local(function, -1, 0);
    if (found.symbol) return found;
    throw Error(
        fmt::format("no variable '{}' in '{}' (or it is an auto of a function that is "
                    "not on the stack)",
                    name, function));
  }
  if (const Symbol* fn = s.function()) {
    const Found found = local(fn->name, s.frame, s.line());
    if (found.symbol) return found;
  }
  for (const Symbol& sym : img.symbols)
    if (sym.kind == Symbol::Kind::Global && sym.name == name) return Found{&sym, -1};
  for (const Symbol& sym : img.symbols)
    if ((sym.kind == Symbol::Kind::Function || sym.kind == Symbol::Kind::Handler) &&
        sym.name == name)
      throw Error(fmt::format("'{}' is a function, not a variable", name));
  const Symbol* fn = s.function();
  throw Error(fmt::format("no variable '{}' in scope{}", name,
                          fn ? fmt::format(" at line {} of {}()", s.line(), fn->name) : ""));
}

Value objectOf(const Scope& s, const Found& found, bool typesOnly) {
  const Symbol& sym = *found.symbol;
  if (sym.typeId < 0) throw Error(fmt::format("'{}' has no type to read it by", sym.name));
  Value v;
  v.type = sym.typeId;
  v.inMemory = true;
  v.known = !typesOnly;
  if (sym.kind == Symbol::Kind::Auto) {
    const vm::Vm::Activation& act = s.activations[static_cast<size_t>(found.frame)];
    if (!act.framed && !typesOnly)
      throw Error(
          fmt::format("'{}' has no frame yet (its function's first instruction, ENTER, "
                      "has not run)",
                      sym.name));
    v.address = static_cast<uint16_t>(act.fp + sym.address);
    v.frame = found.frame;
  } else {
    v.address = static_cast<uint16_t>(sym.address);
  }
  return v;
}

bool namesExist(const vm::Image& image, const Expression& expression) {
  for (const auto& [function, name] : expression.names()) {
    bool found = false;
    for (const Symbol& s : image.symbols) {
      if (s.typeId < 0) continue;
      const auto dot = s.name.find('.');
      if (function.empty())
        found |= (s.kind == Symbol::Kind::Global && s.name == name) ||
                 (dot != std::string::npos && s.name.substr(dot + 1) == name);
      else
        found |= s.name == function + "." + name;
    }
    if (!found) return false;
  }
  return true;
}

std::vector<Variable> locals(const Scope& scope) {
  std::vector<Variable> out;
  const Symbol* fn = scope.function();
  if (!fn) return out;
  const std::string prefix = fn->name + ".";
  std::vector<std::string> names;
  for (const Symbol& sym : scope.image().symbols)
    if (sym.name.rfind(prefix, 0) == 0 && sym.typeId >= 0 &&
        std::find(names.begin(), names.end(), sym.name.substr(prefix.size())) == names.end())
      names.push_back(sym.name.substr(prefix.size()));
  for (const std::string& name : names) {
    try {
      const Found found = lookUp(scope, "", name);
      if (found.symbol && found.symbol->name == prefix + name)
        out.push_back({name, objectOf(scope, found)});
    } catch (const Error&) {
      // Not in scope at this line, or no frame yet: not shown.
    }
  }
  return out;
}

std::vector<Variable> globals(const Scope& scope) {
  std::vector<Variable> out;
  for (const Symbol& sym : scope.image().symbols) {
    if (sym.kind != Symbol::Kind::Global || sym.typeId < 0) continue;
    Value v;
    v.type = sym.typeId;
    v.inMemory = true;
    v.address = static_cast<uint16_t>(sym.address);
    out.push_back({sym.name, v});
  }
  return out;
}

}  // namespace simbot::inspect
