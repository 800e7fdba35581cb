// libFuzzer target: the debugger's expressions (inspect/). Each line of an
// input is one as simbot debug's commands take it -- "EXPR" (print),
// "p/FMT EXPR", "x/NFU EXPR", "ptype EXPR|TYPE" -- parsed, checked as
// --watch checks it before a run, evaluated against a robot stopped in the
// deepest frame of a recursion (tests/debug/inspect.dc: globals of every
// kind, a struct with arrays and a pointer, autos in four frames), and
// printed every way the debugger prints. A bad line must end in one
// inspect::Error; nothing may crash, hang or trip the sanitizers.
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>

#include "compiler/compiler.h"
#include "inspect/inspect.h"
#include "vm/cost.h"
#include "vm/vm.h"

using namespace simbot;

namespace {

class NoBus final : public vm::Bus {
 public:
  void out(timebase::Tick, uint16_t, uint8_t) override {}
  uint8_t in(timebase::Tick, uint16_t) override { return 0xFF; }
  int adSample(timebase::Tick, int) override { return 0; }
};

constexpr size_t kMaxLines = 64;

struct Robot {
  NoBus bus;
  vm::Image image;
  vm::CostTable costs = vm::makeCostTable(vm::uncalibratedKnobs());
  std::unique_ptr<vm::Vm> machine;

  Robot() {
    std::ifstream in(SIMBOT_SOURCE_DIR "/tests/debug/inspect.dc");
    const std::string source((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
    compiler::Result compiled = compiler::compile(source, "inspect.dc");
    if (!compiled.image) std::abort();
    image = std::move(*compiled.image);
    // Stop at "return step;": depth(0, ...) under three more calls of depth.
    int line = 1;
    for (size_t k = 0, at = 0; k < source.size(); ++k)
      if (source[k] == '\n') {
        ++line;
        at = k + 1;
        if (source.compare(at, 20, "        return step;") == 0) break;
      }
    machine = std::make_unique<vm::Vm>(image, bus, costs);
    for (uint32_t a = 0; a < image.lines.size(); ++a)
      if (image.lines[a] == line) {
        machine->setBreakpoint(a);
        break;
      }
    if (machine->run(timebase::Tick{1} << 40) != vm::Stop::Breakpoint) std::abort();
  }
};

void examineLine(const inspect::Scope& scope, const std::string& line) {
  std::string text = line, spec;
  bool examine = false, print = false, ptype = false;
  if (text.rfind("x/", 0) == 0 || text.rfind("p/", 0) == 0) {
    examine = text[0] == 'x';
    print = !examine;
    const auto space = text.find(' ');
    spec = text.substr(1, space == std::string::npos ? std::string::npos : space - 1);
    text = space == std::string::npos ? "" : text.substr(space + 1);
  } else if (text.rfind("ptype ", 0) == 0) {
    ptype = true;
    text = text.substr(6);
  }
  try {
    if (ptype) {
      (void)inspect::describeType(scope, text, true);
      return;
    }
    const inspect::Format how =
        spec.empty() && !print ? inspect::Format{} : inspect::parseFormat(spec, examine);
    const inspect::Expression e(text);
    try {
      inspect::check(scope.image(), e);
    } catch (const inspect::Error&) {
    }
    const inspect::Value v = e.evaluate(scope);
    if (examine) {
      (void)inspect::examine(scope, v, how);
      return;
    }
    (void)inspect::format(scope, v, how);
    (void)inspect::format(scope, v);
    (void)inspect::typeName(scope, v);
    (void)inspect::bytes(scope, v);
    for (const inspect::Child& c : inspect::children(scope, v))
      (void)inspect::hasChildren(scope, c.value);
    int64_t i = 0;
    double r = 0;
    bool f = false;
    (void)inspect::scalar(scope, v, i, r, f);
    (void)inspect::truth(scope, v);
  } catch (const inspect::Error&) {
    // One line for the user: what a bad expression must give.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const Robot robot;
  const inspect::Scope scope(*robot.machine);
  std::istringstream lines(std::string(reinterpret_cast<const char*>(data), size));
  size_t n = 0;
  for (std::string line; n < kMaxLines && std::getline(lines, line); ++n) examineLine(scope, line);
  return 0;
}
