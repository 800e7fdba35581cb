// simbot: the command line. Each subcommand is a thin layer over the parts
// (compiler/, vm/, and later scheduler/ and plant/); see DESIGN.md's tool
// contract for what tests and scripts rely on.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <string>

#include "compiler/compiler.h"
#include "vm/vm.h"

namespace {

int compileCommand(const std::string& file, bool disasm) {
  const auto result = simbot::compiler::compileFile(file);
  if (!result.image) {
    for (const auto& d : result.errors) std::cerr << d.format();
    return 1;
  }
  if (disasm) std::cout << simbot::vm::disassemble(*result.image);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"simbot: a timing-faithful simulator of the 1997 NPS Robot Wars"};
  app.require_subcommand(1);

  std::string compileFile;
  bool disasm = false;
  auto* compile = app.add_subcommand("compile", "compile a Dynamic C program");
  compile->add_option("FILE", compileFile, "program (.dc)")->required();
  compile->add_flag("--disasm", disasm, "print the bytecode, interleaved with the source");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*compile) return compileCommand(compileFile, disasm);
  } catch (const std::exception& e) {
    std::cerr << "simbot: internal error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
