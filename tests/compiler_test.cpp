// Tests of the Dynamic C compiler (compiler/): the two thesis programs, the
// error corpus in tests/errors/, hostile inputs, constant typing, and the
// code shapes the cycle model depends on.
//
// Build: needs compiler/*.cpp (simbot_compiler) and vm/image.cpp
// (Image::functionAt, in simbot_vm), GoogleTest with gtest_main, and the
// macros SIMBOT_SOURCE_DIR (the repository) and SIMBOT_SHARED_DIR (../shared).
#include "compiler/compiler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "compiler/diagnostics.h"
#include "vm/bytecode.h"
#include "vm/image.h"

namespace fs = std::filesystem;
using simbot::compiler::compile;
using simbot::compiler::Options;
using simbot::compiler::Result;
using simbot::vm::Image;
using simbot::vm::Op;
using simbot::vm::Symbol;

namespace {

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> splitLines(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == '\n') {
      if (!cur.empty() && cur.back() == '\r') cur.pop_back();
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

Options noDebug() {
  Options o;
  o.debug = false;
  return o;
}

Image mustCompile(const std::string& source, const std::string& name = "test.dc",
                  const Options& options = {}) {
  Result r = compile(source, name, options);
  EXPECT_TRUE(r.image.has_value()) << (r.errors.empty() ? "" : r.errors[0].format());
  EXPECT_TRUE(r.errors.empty());
  if (!r.image) return Image{};
  return *r.image;
}

const Symbol* findSymbol(const Image& img, const std::string& name) {
  for (const Symbol& s : img.symbols)
    if (s.name == name) return &s;
  return nullptr;
}

struct Insn {
  uint32_t addr;
  Op op;
  int32_t operand;  // U16, REL16 (as the absolute target), I32; LIB: id
};

// Decodes [begin, end) of the code.
std::vector<Insn> decode(const Image& img, uint32_t begin, uint32_t end) {
  std::vector<Insn> out;
  for (uint32_t pc = begin; pc < end;) {
    Op op = static_cast<Op>(img.code.at(pc));
    const auto& info = simbot::vm::info(op);
    int32_t operand = 0;
    const uint8_t* p = img.code.data() + pc + 1;
    switch (info.shape) {
      case simbot::vm::Shape::U8:
        operand = p[0];
        break;
      case simbot::vm::Shape::U16:
      case simbot::vm::Shape::CO:  // the CoData address
        operand = p[0] | (p[1] << 8);
        break;
      case simbot::vm::Shape::REL16:
        operand = static_cast<int32_t>(pc + 3) + static_cast<int16_t>(p[0] | (p[1] << 8));
        break;
      case simbot::vm::Shape::I32:
      case simbot::vm::Shape::F32:
        std::memcpy(&operand, p, 4);
        break;
      case simbot::vm::Shape::LIB:
        operand = p[0];
        break;
      case simbot::vm::Shape::NONE:
        break;
    }
    out.push_back(Insn{pc, op, operand});
    pc += static_cast<uint32_t>(simbot::vm::instructionSize(op));
  }
  return out;
}

std::vector<Insn> functionCode(const Image& img, const std::string& name) {
  const Symbol* s = findSymbol(img, name);
  EXPECT_NE(s, nullptr) << name;
  if (!s) return {};
  return decode(img, s->address, s->address + s->size);
}

int count(const std::vector<Insn>& code, Op op) {
  return static_cast<int>(
      std::count_if(code.begin(), code.end(), [&](const Insn& i) { return i.op == op; }));
}

uint32_t dataWord(const Image& img, const std::string& name) {
  const Symbol* s = findSymbol(img, name);
  EXPECT_NE(s, nullptr) << name;
  if (!s) return 0;
  size_t off = s->address - simbot::vm::kDataBase;
  uint32_t v = 0;
  for (uint32_t i = 0; i < s->size && i < 4; ++i)
    v |= static_cast<uint32_t>(img.data.at(off + i)) << (8 * i);
  return v;
}

// An error result: at least one diagnostic and at most the cap (plus the
// line saying so), each of the right shape.
void expectError(const Result& r) {
  ASSERT_FALSE(r.image.has_value());
  ASSERT_GE(r.errors.size(), 1u);
  ASSERT_LE(r.errors.size(), static_cast<size_t>(simbot::compiler::kMaxErrors) + 1);
  for (const auto& d : r.errors) {
    EXPECT_GE(d.line, 1);
    EXPECT_GE(d.column, 1);
    EXPECT_FALSE(d.message.empty());
    EXPECT_NE(d.format().find(": error: "), std::string::npos);
  }
}

// ---------------------------------------------------------------------------
// The thesis programs.

TEST(CompilerPrograms, IcemanCompiles) {
  fs::path p = fs::path(SIMBOT_SHARED_DIR) / "programs" / "iceman.dc";
  Image img = mustCompile(readFile(p), "iceman.dc");
  ASSERT_FALSE(img.code.empty());

  ASSERT_EQ(img.vectors.size(), 1u);
  EXPECT_EQ(img.vectors[0].vector, 0x10);
  EXPECT_EQ(img.vectors[0].handlerName, "INT1");
  const Symbol* h = findSymbol(img, "INT1");
  ASSERT_NE(h, nullptr);
  EXPECT_EQ(h->kind, Symbol::Kind::Handler);
  EXPECT_EQ(img.vectors[0].handler, h->address);
  // The handler ends in RETI and is never called.
  auto hcode = functionCode(img, "INT1");
  ASSERT_FALSE(hcode.empty());
  EXPECT_EQ(hcode.back().op, Op::RETI);
  for (const Insn& i : decode(img, 0, static_cast<uint32_t>(img.code.size())))
    if (i.op == Op::CALL) {
      EXPECT_NE(static_cast<uint32_t>(i.operand), h->address);
    }

  // count<50000 compares longs: 50000 does not fit an int.
  auto mainCode = functionCode(img, "main");
  EXPECT_GT(count(mainCode, Op::LTUL) + count(mainCode, Op::LTL), 0);
  bool pushed50000 = std::any_of(mainCode.begin(), mainCode.end(), [](const Insn& i) {
    return i.op == Op::PUSHL && i.operand == 50000;
  });
  EXPECT_TRUE(pushed50000);
  // count++ on the unsigned long global: INCGL.
  const Symbol* countSym = findSymbol(img, "count");
  ASSERT_NE(countSym, nullptr);
  EXPECT_EQ(countSym->type, "unsigned long");
  EXPECT_TRUE(std::any_of(mainCode.begin(), mainCode.end(), [&](const Insn& i) {
    return i.op == Op::INCGL && static_cast<uint32_t>(i.operand) == countSym->address;
  }));

  // Start-up stub: CALL main; POP; HALT at 0.
  EXPECT_EQ(img.entry, 0);
  auto stub = decode(img, 0, 5);
  ASSERT_EQ(stub.size(), 3u);
  EXPECT_EQ(stub[0].op, Op::CALL);
  EXPECT_EQ(static_cast<uint32_t>(stub[0].operand), findSymbol(img, "main")->address);
  EXPECT_EQ(stub[1].op, Op::POP);
  EXPECT_EQ(stub[2].op, Op::HALT);

  // Globals are packed from kDataBase in declaration order.
  EXPECT_EQ(findSymbol(img, "buf")->address, simbot::vm::kDataBase);
  EXPECT_EQ(findSymbol(img, "buf")->size, 9u);
  EXPECT_EQ(findSymbol(img, "cc")->address, simbot::vm::kDataBase + 9u);
  EXPECT_NE(findSymbol(img, "INT1.data"), nullptr);
  EXPECT_EQ(findSymbol(img, "INT1.data")->kind, Symbol::Kind::Static);
  EXPECT_EQ(img.sourceLines.size(), splitLines(readFile(p)).size());
}

TEST(CompilerPrograms, Fig92Compiles) {
  fs::path p = fs::path(SIMBOT_SHARED_DIR) / "programs" / "fig92.dc";
  Image img = mustCompile(readFile(p), "fig92.dc");
  ASSERT_FALSE(img.code.empty());
  EXPECT_TRUE(img.vectors.empty());
  auto mainCode = functionCode(img, "main");
  EXPECT_GT(count(mainCode, Op::W2F), 0);    // left = ad_rd8(0)
  EXPECT_GT(count(mainCode, Op::LTF), 0);    // sum < 400
  EXPECT_GT(count(mainCode, Op::DECGW), 0);  // ammo--
  EXPECT_EQ(findSymbol(img, "left")->type, "float");
}

TEST(CompilerPrograms, LineTableCoversEveryCodeByte) {
  for (const char* name : {"iceman.dc", "fig92.dc"}) {
    Image img = mustCompile(readFile(fs::path(SIMBOT_SHARED_DIR) / "programs" / name), name);
    ASSERT_EQ(img.lines.size(), img.code.size()) << name;
    for (size_t i = 0; i < img.lines.size(); ++i) {
      EXPECT_GE(img.lines[i], 1) << name << " byte " << i;
      EXPECT_LE(img.lines[i], static_cast<int>(img.sourceLines.size())) << name << " byte " << i;
    }
    // Every instruction's bytes share one line.
    for (const Insn& in : decode(img, 0, static_cast<uint32_t>(img.code.size())))
      for (int k = 1; k < simbot::vm::instructionSize(in.op); ++k)
        EXPECT_EQ(img.lines[in.addr + k], img.lines[in.addr]);
  }
}

// The delay loop of platform(): INCGW, and exactly one DBG per iteration.
TEST(CompilerCodeShape, DelayLoopOneDbgPerIteration) {
  Image img = mustCompile(
      "platform()\n"
      "{\n"
      "    int z;\n"
      "    for(z=0;z<700;z++);\n"
      "}\n"
      "main() { platform(); }\n");
  auto code = functionCode(img, "platform");
  const Symbol* z = findSymbol(img, "platform.z");
  ASSERT_NE(z, nullptr);
  EXPECT_EQ(z->kind, Symbol::Kind::Static);
  // The loop: a backward JMP to its condition.
  auto back = std::find_if(code.begin(), code.end(), [](const Insn& i) {
    return i.op == Op::JMP && static_cast<uint32_t>(i.operand) < i.addr;
  });
  ASSERT_NE(back, code.end());
  auto top = std::find_if(code.begin(), code.end(), [&](const Insn& i) {
    return i.addr == static_cast<uint32_t>(back->operand);
  });
  ASSERT_NE(top, code.end());
  std::vector<Insn> loop(top, back + 1);
  EXPECT_EQ(count(loop, Op::DBG), 1);
  EXPECT_EQ(count(loop, Op::INCGW), 1);
  EXPECT_EQ(count(loop, Op::POP), 0);
  auto inc =
      std::find_if(loop.begin(), loop.end(), [](const Insn& i) { return i.op == Op::INCGW; });
  EXPECT_EQ(static_cast<uint32_t>(inc->operand), z->address);
  // Condition: LDGW z; PUSHW 700; LTW; JZ.
  ASSERT_GE(loop.size(), 4u);
  EXPECT_EQ(loop[0].op, Op::LDGW);
  EXPECT_EQ(loop[1].op, Op::PUSHW);
  EXPECT_EQ(loop[1].operand, 700);
  EXPECT_EQ(loop[2].op, Op::LTW);
  EXPECT_EQ(loop[3].op, Op::JZ);
}

TEST(CompilerCodeShape, SuperInstructionsAndStatementStores) {
  Image img = mustCompile(
      "int i; unsigned u; long l; unsigned long ul; char c; int *p;\n"
      "main() {\n"
      "  i++; ++i; i += 1; i--; --i; i -= 1;\n"
      "  u++; l++; ul += 1; l--;\n"
      "  c++; p++;\n"
      "  i = 5;\n"
      "}\n",
      "t.dc", noDebug());
  auto code = functionCode(img, "main");
  EXPECT_EQ(count(code, Op::INCGW), 4);  // i++ ++i i+=1 u++
  EXPECT_EQ(count(code, Op::DECGW), 3);
  EXPECT_EQ(count(code, Op::INCGL), 2);  // l++ ul+=1 (l-- is not one)
  EXPECT_EQ(count(code, Op::DBG), 0);    // debug off
  EXPECT_EQ(count(code, Op::DUP), 0);    // no value is kept
  // c++: LDGB PUSHW 1 ADDW STGB; i = 5: PUSHW 5 STGW (no DUP/POP).
  EXPECT_EQ(count(code, Op::STGB), 1);
  EXPECT_EQ(count(code, Op::W2B), 0);
  auto last = code.end() - 2;  // ... PUSHW 5; STGW i; PUSHW 0; RET
  EXPECT_EQ((last - 1)->op, Op::STGW);
  EXPECT_EQ((last - 2)->op, Op::PUSHW);
  EXPECT_EQ((last - 2)->operand, 5);
}

TEST(CompilerCodeShape, DebugHooksFollowNodebug) {
  const char* src =
      "int x;\n"
      "f() { x = 1; x = 2; }\n"
      "nodebug g() { x = 3; }\n"
      "#nodebug\n"
      "h() { x = 4; }\n"
      "#debug\n"
      "main() { ; f(); g(); h(); }\n";
  Image img = mustCompile(src);
  EXPECT_EQ(count(functionCode(img, "f"), Op::DBG), 2);
  EXPECT_EQ(count(functionCode(img, "g"), Op::DBG), 0);
  EXPECT_EQ(count(functionCode(img, "h"), Op::DBG), 0);
  EXPECT_EQ(count(functionCode(img, "main"), Op::DBG), 4);  // the empty statement too
  Image off = mustCompile(src, "t.dc", noDebug());
  EXPECT_EQ(count(decode(off, 0, static_cast<uint32_t>(off.code.size())), Op::DBG), 0);
}

TEST(CompilerCodeShape, ClassAutoUsesFrames) {
  Image img = mustCompile(
      "#class auto\n"
      "int fact(int n) { int r; if (n <= 1) return 1; r = n * fact(n - 1); return r; }\n"
      "#class static\n"
      "int s(int m) { return m; }\n"
      "main() { fact(5); s(1); }\n",
      "t.dc", noDebug());
  auto f = functionCode(img, "fact");
  ASSERT_FALSE(f.empty());
  EXPECT_EQ(f[0].op, Op::ENTER);
  EXPECT_EQ(f[0].operand, 4);
  EXPECT_EQ(f[1].op, Op::STLW);  // the parameter popped into its slot
  EXPECT_GT(count(f, Op::LDLW), 0);
  EXPECT_EQ(findSymbol(img, "fact.r")->kind, Symbol::Kind::Auto);
  EXPECT_EQ(findSymbol(img, "fact.r")->address, 2u);
  auto s = functionCode(img, "s");
  EXPECT_EQ(s[0].op, Op::STGW);
  EXPECT_EQ(findSymbol(img, "s.m")->kind, Symbol::Kind::Param);
}

TEST(CompilerCodeShape, BuiltinsAndIntrinsics) {
  Image img = mustCompile(
      "char buf[9]; char cc;\n"
      "main() { EI(); DI(); cc = sizeof(buf); ser_send_z1(buf, &cc); strcpy(buf, \"abc\");\n"
      "  printf(\"%d %c\\n\", cc, cc); }\n",
      "t.dc", noDebug());
  auto code = functionCode(img, "main");
  EXPECT_EQ(count(code, Op::EI), 1);
  EXPECT_EQ(count(code, Op::DI), 1);
  EXPECT_EQ(count(code, Op::LIB), 3);
  // cc = sizeof(buf): PUSHW 9.
  EXPECT_TRUE(std::any_of(code.begin(), code.end(),
                          [](const Insn& i) { return i.op == Op::PUSHW && i.operand == 9; }));
  // strcpy's pointer result is dropped, ser_send_z1 has none; printf's is dropped.
  EXPECT_EQ(count(code, Op::POP), 2);
}

// ---------------------------------------------------------------------------
// Constant typing (DESIGN.md): folded into the initial data.

TEST(CompilerConstants, DecimalHexAndSuffixTyping) {
  Image img = mustCompile(
      "int s1 = sizeof(50000);  int n1 = 50000 > -1;\n"
      "int s2 = sizeof(32767);  int n2 = 32767 > -1;\n"
      "int s3 = sizeof(0xffff); int n3 = 0xffff > -1;\n"
      "int s4 = sizeof(0x10000); int n4 = 0x10000 > -1;\n"
      "int s5 = sizeof(40000u); int n5 = 40000u > -1;\n"
      "int s6 = sizeof(32768); int s7 = sizeof(0x8000); int n7 = 0x8000 > -1;\n"
      "int s8 = sizeof(2147483648); int n8 = 2147483648 > -1;\n"
      "int s9 = sizeof('a'); int s10 = sizeof(1.5); int s11 = sizeof(10L);\n"
      "int r1 = 9600/1200; int r2 = -1; unsigned r3 = -1; char r4 = 300; long r5 = 70000;\n"
      "main() { }\n");
  EXPECT_EQ(dataWord(img, "s1"), 4u);  // long
  EXPECT_EQ(dataWord(img, "n1"), 1u);
  EXPECT_EQ(dataWord(img, "s2"), 2u);  // int
  EXPECT_EQ(dataWord(img, "n2"), 1u);
  EXPECT_EQ(dataWord(img, "s3"), 2u);  // unsigned int: -1 becomes 0xffff
  EXPECT_EQ(dataWord(img, "n3"), 0u);
  EXPECT_EQ(dataWord(img, "s4"), 4u);  // long
  EXPECT_EQ(dataWord(img, "n4"), 1u);
  EXPECT_EQ(dataWord(img, "s5"), 2u);  // unsigned int
  EXPECT_EQ(dataWord(img, "n5"), 0u);
  EXPECT_EQ(dataWord(img, "s6"), 4u);  // decimal 32768: long
  EXPECT_EQ(dataWord(img, "s7"), 2u);  // hex 0x8000: unsigned int
  EXPECT_EQ(dataWord(img, "n7"), 0u);
  EXPECT_EQ(dataWord(img, "s8"), 4u);  // unsigned long
  EXPECT_EQ(dataWord(img, "n8"), 0u);
  EXPECT_EQ(dataWord(img, "s9"), 2u);
  EXPECT_EQ(dataWord(img, "s10"), 4u);
  EXPECT_EQ(dataWord(img, "s11"), 4u);
  EXPECT_EQ(dataWord(img, "r1"), 8u);
  EXPECT_EQ(dataWord(img, "r2"), 0xFFFFu);
  EXPECT_EQ(dataWord(img, "r3"), 0xFFFFu);
  EXPECT_EQ(dataWord(img, "r4"), 44u);
  EXPECT_EQ(dataWord(img, "r5"), 70000u);
}

TEST(CompilerConstants, StringsAndInitialisers) {
  Image img = mustCompile(
      "char msg[] = \"ab\" \"c\";\n"
      "char *p = \"xyz\";\n"
      "int a[4] = { 1, 2 };\n"
      "struct { char c; int w; } s = { 'q', -2 };\n"
      "main() { }\n");
  const Symbol* msg = findSymbol(img, "msg");
  ASSERT_NE(msg, nullptr);
  EXPECT_EQ(msg->size, 4u);
  EXPECT_EQ(msg->type, "char[4]");
  size_t m = msg->address - simbot::vm::kDataBase;
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(img.data.data() + m)), "abc");
  uint32_t str = dataWord(img, "p");
  EXPECT_EQ(
      std::string(reinterpret_cast<const char*>(img.data.data() + (str - simbot::vm::kDataBase))),
      "xyz");
  size_t a = findSymbol(img, "a")->address - simbot::vm::kDataBase;
  EXPECT_EQ(img.data[a], 1);
  EXPECT_EQ(img.data[a + 2], 2);
  EXPECT_EQ(img.data[a + 4], 0);
  size_t s = findSymbol(img, "s")->address - simbot::vm::kDataBase;
  EXPECT_EQ(img.data[s], 'q');
  EXPECT_EQ(img.data[s + 1], 0xFE);  // packed: no alignment
  EXPECT_EQ(img.data[s + 2], 0xFF);
}

// ---------------------------------------------------------------------------
// The error corpus: tests/errors/*.dc with "// expect-error: L:C: MESSAGE" on
// the first lines, one per error the file must report (all of them, in
// order), or entries in tests/errors/expectations.txt.

struct Expected {
  int line = 0, col = 0;
  std::string message;
};

bool parseExpectation(const std::string& text, Expected& e) {
  size_t c1 = text.find(':');
  if (c1 == std::string::npos) return false;
  size_t c2 = text.find(':', c1 + 1);
  if (c2 == std::string::npos) return false;
  e.line = std::stoi(text.substr(0, c1));
  e.col = std::stoi(text.substr(c1 + 1, c2 - c1 - 1));
  e.message = text.substr(c2 + 1);
  if (!e.message.empty() && e.message[0] == ' ') e.message.erase(0, 1);
  while (!e.message.empty() && (e.message.back() == '\r' || e.message.back() == ' '))
    e.message.pop_back();
  return true;
}

std::string expectedFormat(const std::string& name, const std::string& source, const Expected& e) {
  std::vector<std::string> lines = splitLines(source);
  std::string text =
      e.line >= 1 && static_cast<size_t>(e.line) <= lines.size() ? lines[e.line - 1] : "";
  std::string caret;
  for (int i = 0; i + 1 < e.col; ++i)
    caret += (i < static_cast<int>(text.size()) && text[i] == '\t') ? '\t' : ' ';
  return name + ":" + std::to_string(e.line) + ":" + std::to_string(e.col) +
         ": error: " + e.message + "\n" + text + "\n" + caret + "^\n";
}

TEST(CompilerErrors, CorpusMatchesExpectedDiagnostics) {
  fs::path dir = fs::path(SIMBOT_SOURCE_DIR) / "tests" / "errors";
  std::map<std::string, std::vector<Expected>> table;
  {
    std::istringstream in(readFile(dir / "expectations.txt"));
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      size_t sp = line.find(' ');
      Expected e;
      ASSERT_TRUE(sp != std::string::npos && parseExpectation(line.substr(sp + 1), e)) << line;
      table[line.substr(0, sp)].push_back(e);
    }
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".dc") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 40u);
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.filename().string());
    std::string name = f.filename().string();
    std::string source = readFile(f);
    std::vector<Expected> expected;
    const std::string marker = "// expect-error:";
    for (size_t at = 0; source.compare(at, marker.size(), marker) == 0;) {
      size_t end = source.find('\n', at);
      Expected e;
      ASSERT_TRUE(parseExpectation(source.substr(at + marker.size(), end - at - marker.size()), e));
      expected.push_back(e);
      if (end == std::string::npos) break;
      at = end + 1;
    }
    if (expected.empty()) {
      ASSERT_TRUE(table.count(name)) << "no expectation for " << name;
      expected = table[name];
    }
    Result r = compile(source, name);
    ASSERT_FALSE(r.image.has_value());
    std::string got;
    for (const auto& d : r.errors) got += d.format();
    ASSERT_EQ(r.errors.size(), expected.size()) << got;
    for (size_t k = 0; k < expected.size(); ++k) {
      const Expected& e = expected[k];
      // Lines that are long or hold control characters are shown cut or
      // cleaned (DiagnosticCutsLongLines, ...ControlCharacters): for those the
      // corpus checks the first line only.
      const std::string want = expectedFormat(name, source, e);
      const std::string header = want.substr(0, want.find('\n') + 1);
      const std::string shownLine =
          want.substr(header.size(), want.find('\n', header.size()) - header.size());
      const bool plain =
          shownLine.size() <= 160 && std::none_of(shownLine.begin(), shownLine.end(), [](char c) {
            return (static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f;
          });
      if (plain)
        EXPECT_EQ(r.errors[k].format(), want);
      else
        EXPECT_EQ(r.errors[k].format().substr(0, header.size()), header);
    }
  }
}

// A 1,000-character line with an error at column 600: 160 characters are
// shown, from column 600 - 80 = 520 (index 519), between ellipses, and the
// caret sits under column 600: 3 + (599 - 519) = 83 columns in.
TEST(CompilerErrors, DiagnosticCutsLongLines) {
  std::string line = "int x = 1" + std::string(590, ' ') + "@" + std::string(399, ' ') + ";";
  ASSERT_EQ(line.size(), 1000u);
  ASSERT_EQ(line[599], '@');
  Result r = compile("main()\n{\n" + line + "\n}\n", "long.dc");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].format(), "long.dc:3:600: error: invalid character\n..." +
                                      line.substr(519, 160) + "...\n" + std::string(83, ' ') +
                                      "^\n");
}

TEST(CompilerErrors, DiagnosticShowsControlCharactersAsQuestionMarks) {
  Result r = compile(std::string("main()\n{\n\tx\x01\x1b = 1;\n}\n"), "ctl.dc");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].format(), "ctl.dc:3:3: error: invalid character\n\tx?? = 1;\n\t ^\n");
}

TEST(CompilerErrors, DiagnosticFormatKeepsTabs) {
  Result r = compile("main()\n{\n\tint x;\n\tx = \t@;\n}\n", "tab.dc");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].format(), "tab.dc:4:7: error: invalid character\n\tx = \t@;\n\t    \t^\n");
}

// A byte order mark before the program is dropped, and line 1's columns are
// counted from the character after it: in `int x = @;` the `@` is the 9th.
TEST(CompilerErrors, AByteOrderMarkIsNoPartOfTheProgram) {
  Result ok = compile("\xEF\xBB\xBFmain() { }\n", "bom.dc");
  EXPECT_TRUE(ok.errors.empty());
  EXPECT_TRUE(ok.image.has_value());
  Result r = compile("\xEF\xBB\xBFint x = @;\n", "bom.dc");
  ASSERT_FALSE(r.errors.empty());
  EXPECT_EQ(r.errors[0].format().substr(0, 36), "bom.dc:1:9: error: invalid character");
}

// ---------------------------------------------------------------------------
// Hostile inputs: each is one clean error, no crash, no hang.

TEST(CompilerRobustness, DeeplyNestedParentheses) {
  std::string s =
      "int x; main() { x = " + std::string(100000, '(') + "1" + std::string(100000, ')') + "; }";
  Result r = compile(s, "parens.dc");
  expectError(r);
  EXPECT_EQ(r.errors[0].message, "nesting too deep");
}

TEST(CompilerRobustness, DeeplyNestedBlocks) {
  std::string s = "main()" + std::string(10000, '{') + std::string(10000, '}');
  Result r = compile(s, "blocks.dc");
  expectError(r);
  EXPECT_EQ(r.errors[0].message, "nesting too deep");
}

TEST(CompilerRobustness, DeeplyNestedConditionals) {
  std::string s;
  for (int i = 0; i < 5000; ++i) s += "#if 1\n";
  s += "main() { }\n";
  for (int i = 0; i < 5000; ++i) s += "#endif\n";
  expectError(compile(s, "ifs.dc"));
}

TEST(CompilerRobustness, LongOperatorChains) {
  std::string terms = "x";
  for (int i = 0; i < 100000; ++i) terms += "+x";
  expectError(compile("int x; main() { x = " + terms + "; }", "chain.dc"));
  std::string unary(100000, '!');
  expectError(compile("int x; main() { x = " + unary + "x; }", "unary.dc"));
  std::string stars(100000, '*');
  expectError(compile("int " + stars + "p; main() { }", "stars.dc"));
}

TEST(CompilerRobustness, SelfReferentialMacros) {
  expectError(compile("#define X X\nmain() { X; }\n", "self.dc"));
  expectError(compile("#define f(x) f(f(x))\nmain() { f(1); }\n", "selff.dc"));
  // Exponential growth is capped.
  std::string s;
  for (char c = 'a'; c < 'y'; ++c)
    s += std::string("#define ") + c + " " + char(c + 1) + " " + char(c + 1) + "\n";
  s += "#define y 1+\nint v = a 0;\nmain() { }\n";
  expectError(compile(s, "growth.dc"));
  std::string nested = "#define f(x) x\nint v = ";
  for (int i = 0; i < 10000; ++i) nested += "f(";
  nested += "1" + std::string(10000, ')') + ";\nmain() { }\n";
  expectError(compile(nested, "nested.dc"));
}

TEST(CompilerRobustness, RandomBytes) {
  std::mt19937 rng(12345);
  std::string s(1 << 20, '\0');
  for (char& c : s) c = static_cast<char>(rng() & 0xFF);
  expectError(compile(s, "random.dc"));
  // Random C-ish tokens.
  const char* pieces[] = {"(", ")", "{",    "}",       "int", "x",     ";",   "=",
                          "+", "*", "if",   "while",   "1",   "\"s\"", "'c'", ",",
                          "[", "]", "main", "#define", "\n",  "->",    "."};
  for (int round = 0; round < 200; ++round) {
    std::string t;
    for (int i = 0; i < 300; ++i) t += std::string(pieces[rng() % std::size(pieces)]) + " ";
    Result r = compile(t, "fuzz.dc");
    if (!r.image) expectError(r);
  }
}

TEST(CompilerRobustness, EmptyAndTinyInputs) {
  Result r = compile("", "empty.dc");
  expectError(r);
  EXPECT_EQ(r.errors[0].message, "no main function");
  EXPECT_EQ(r.errors[0].line, 1);
  EXPECT_EQ(r.errors[0].column, 1);
  expectError(compile("\0", "nul.dc"));
  expectError(compile(std::string(1, '\0'), "nul.dc"));
  expectError(compile("/*", "c.dc"));
  expectError(compile("\"", "q.dc"));
  expectError(compile("#", "h.dc"));
  expectError(compile("#define", "d.dc"));
  expectError(compile("#if", "i.dc"));
  expectError(compile("main(", "m.dc"));
}

TEST(CompilerRobustness, MissingFile) {
  Result r = simbot::compiler::compileFile("/nonexistent/dir/robot.dc");
  expectError(r);
}

// ---------------------------------------------------------------------------
// Every error of a file, and the warnings (docs/language.md, "Warnings").

// Each warning as "LINE:COL NAME"; the source must compile.
std::vector<std::string> warned(const std::string& source, const Options& options = {}) {
  Result r = compile(source, "w.dc", options);
  EXPECT_TRUE(r.errors.empty()) << (r.errors.empty() ? "" : r.errors[0].format());
  std::vector<std::string> out;
  for (const auto& d : r.warnings) {
    EXPECT_EQ(d.severity, simbot::compiler::Severity::Warning);
    out.push_back(std::to_string(d.line) + ":" + std::to_string(d.column) + " " + d.warning);
  }
  return out;
}

using Strings = std::vector<std::string>;

TEST(CompilerDiagnostics, FiveIndependentMistakesAllReported) {
  const std::string src =
      "int speed;\n"                           // 1
      "int bad bad;\n"                         // 2: ';' expected after "bad" (col 8)
      "main()\n"                               // 3
      "{\n"                                    // 4
      "    int count;\n"                       // 5
      "    speed = 3\n"                        // 6: ';' expected after "3" (col 14)
      "    count = 0;\n"                       // 7: eaten by line 6's recovery
      "    speed = speed * 2;\n"               // 8
      "    count = count + ;\n"                // 9: ';' at col 21 is no expression
      "    unknown = 5;\n"                     // 10: col 5
      "    while (count < 10) {\n"             // 11
      "        count++;\n"                     // 12
      "        if (count == 3) return 4 5;\n"  // 13: after "4" (col 32): col 33
      "    }\n"                                // 14
      "}\n";                                   // 15
  Result r = compile(src, "five.dc");
  ASSERT_FALSE(r.image.has_value());
  EXPECT_TRUE(r.warnings.empty());
  std::string got;
  for (const auto& d : r.errors) got += d.format();
  EXPECT_EQ(got,
            "five.dc:2:8: error: expected ';' after declaration\nint bad bad;\n       ^\n"
            "five.dc:6:14: error: expected ';' after expression\n    speed = 3\n             ^\n"
            "five.dc:9:21: error: expected expression\n    count = count + ;\n"
            "                    ^\n"
            "five.dc:10:5: error: undeclared identifier 'unknown'\n    unknown = 5;\n    ^\n"
            "five.dc:13:33: error: expected ';' after return statement\n"
            "        if (count == 3) return 4 5;\n                                ^\n");
}

TEST(CompilerDiagnostics, NoCascadeAfterAFailedDeclaration) {
  // "widget" is no type: the declaration fails, and the uses of "w" and the
  // call of the failed function "f" are not reported again.
  Result r = compile(
      "widget w;\n"
      "int f(int a b) { return a; }\n"
      "main() { w = 1; f(2); }\n",
      "c.dc");
  ASSERT_EQ(r.errors.size(), 2u);
  EXPECT_EQ(r.errors[0].line, 1);  // unknown type name 'widget', col 1
  EXPECT_EQ(r.errors[0].column, 1);
  EXPECT_EQ(r.errors[1].line, 2);  // expected ')' at "b", col 13
  EXPECT_EQ(r.errors[1].column, 13);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(CompilerDiagnostics, AnonymousMemberIsRefusedOnceAndItsStructNotAgain) {
  // C11's anonymous struct member (Dynamic C had none) is refused where it
  // is, col 36 (the ';' after its '}'), and the struct it was in, which
  // stays incomplete, is not reported again at each use: the object of its
  // type (line 2), sizeof and a member access (line 3). A struct never
  // declared still is (line 4, col 10).
  Result r = compile(
      "struct s { int a; struct { int b; }; };\n"
      "struct s v;\n"
      "main() { v.a = 1; printf(\"%d\", sizeof(struct s)); }\n"
      "struct q w;\n",
      "a.dc");
  ASSERT_EQ(r.errors.size(), 2u);
  EXPECT_EQ(r.errors[0].format().rfind(
                "a.dc:1:36: error: anonymous struct or union members are not supported", 0),
            0u)
      << r.errors[0].format();
  EXPECT_EQ(r.errors[1].format().rfind("a.dc:4:10: error: storage size of 'w' is not known", 0), 0u)
      << r.errors[1].format();
}

TEST(CompilerDiagnostics, MissingCloseBraceEndsAtTheNextFunction) {
  // main's '}' is missing: one error, just after the last '}' read (line 6,
  // col 2), and platform() and the handler parse as functions of their own.
  Result r = compile(
      "int x;\n"
      "main()\n"
      "{\n"
      "    while (1) {\n"
      "        x = 1;\n"
      "}\n"
      "platform()\n"
      "{\n"
      "    x = 2;\n"
      "}\n"
      "#INT_VEC PIOA_VEC edge\n"
      "interrupt reti edge() { x = 3; }\n",
      "b.dc");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].format(),
            "b.dc:6:2: error: expected '}' before the definition of 'platform'\n}\n ^\n");
  // A mistyped "if" ("f(x == 1) {") is a statement gone wrong, not a function.
  Result m = compile("int x;\nmain()\n{\nf(x == 1) { x = 2; }\n}\n", "m.dc");
  ASSERT_EQ(m.errors.size(), 2u);
  EXPECT_EQ(m.errors[0].message, "undefined function 'f'");
  EXPECT_EQ(m.errors[1].message, "expected ';' after expression");
}

TEST(CompilerDiagnostics, UndeclaredReportedOncePerFunction) {
  Result r = compile("main() { y = 1; y = 2; }\nf() { y = 3; }\n", "u.dc");
  ASSERT_EQ(r.errors.size(), 2u);
  EXPECT_EQ(r.errors[0].line, 1);  // col 10, main's first use
  EXPECT_EQ(r.errors[0].column, 10);
  EXPECT_EQ(r.errors[1].line, 2);  // col 7, f's
  EXPECT_EQ(r.errors[1].column, 7);
}

TEST(CompilerDiagnostics, ErrorsAreCapped) {
  std::string src = "main() {\n";
  for (int i = 0; i < 80; ++i) src += "  x" + std::to_string(i) + " = 1;\n";
  src += "}\n";
  Result r = compile(src, "cap.dc");
  ASSERT_EQ(r.errors.size(), static_cast<size_t>(simbot::compiler::kMaxErrors) + 1);
  EXPECT_EQ(r.errors.back().message, "too many errors (50), stopping here");
}

TEST(CompilerWarnings, TautologicalCompare) {
  // Line 2: "i<50000" with '<' at col 23 (after the 22 bytes "main(){int j;for(i=0;i").
  EXPECT_EQ(warned("int i;\nmain(){int j;for(i=0;i<50000;i++);j=0;}\n"),
            Strings{"2:23 tautological-compare"});
  // "==" at col 12 of "main(){if(c==-1)c=1;}": a char is never -1.
  EXPECT_EQ(warned("char c;\nmain(){if(c==-1)c=1;}\n"), Strings{"2:12 tautological-compare"});
  // A long counter, and an int compared within its range: nothing.
  EXPECT_EQ(warned("long i;\nmain(){for(i=0;i<50000;i++);}\n"), Strings{});
  EXPECT_EQ(warned("int i;\nmain(){for(i=0;i<30000;i++);}\n"), Strings{});
}

TEST(CompilerWarnings, AssignmentAsCondition) {
  // The '=' of "x = 5" at col 16 ("main() { if (x " is 15 bytes).
  EXPECT_EQ(warned("int x;\nmain() { if (x = 5) x = 1; }\n"), Strings{"2:16 parentheses"});
  EXPECT_EQ(warned("int x;\nmain() { while (x = 0) ; }\n"), Strings{"2:19 parentheses"});
  EXPECT_EQ(warned("int x;\nmain() { if ((x = 5)) x = 1; if (x == 5) x = 2; }\n"), Strings{});
}

TEST(CompilerWarnings, UnboundHandler) {
  EXPECT_EQ(warned("interrupt reti edge() { }\nmain() { }\n"), Strings{"1:16 unbound-handler"});
  EXPECT_EQ(warned("#INT_VEC PIOA_VEC edge\ninterrupt reti edge() { }\nmain() { }\n"), Strings{});
}

TEST(CompilerWarnings, DefineIntVec) {
  // The thesis's extracted form; the handler is then unbound as well.
  EXPECT_EQ(warned("#define INT_VEC PIOA_VEC rimint\ninterrupt reti rimint() { }\nmain() { }\n"),
            (Strings{"1:1 define-int-vec", "2:16 unbound-handler"}));
  Result r = compile("#define INT_VEC PIOA_VEC rimint\nmain() { }\n", "d.dc");
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].message.find("did you mean '#INT_VEC PIOA_VEC rimint'"),
            std::string::npos);
  EXPECT_EQ(warned("#define VEC PIOA_VEC\nmain() { }\n"), Strings{});
}

TEST(CompilerWarnings, Uninitialized) {
  // "n" is read (line 3, col 7) and never assigned anywhere in main.
  EXPECT_EQ(warned("int x;\nmain() { int n;\n  x = n;\n}\n"), Strings{"3:7 uninitialized"});
  // Read before the assignment, but assigned in the loop: a deliberate use of
  // the static's value from the previous pass. ++, &n and initialisers count.
  EXPECT_EQ(warned("int x;\nmain() { int n; while (x < 3) { if (n) x++; n = 1; } }\n"), Strings{});
  EXPECT_EQ(warned("int x;\nmain() { int n, m = 2, *p; n++; p = &x; x = n + m + *p; }\n"),
            Strings{});
}

// Issue 25: a global (or file-level static) scalar read somewhere and
// assigned nowhere in the whole program.
TEST(CompilerWarnings, UninitializedGlobal) {
  // "g" read at line 2 col 21, never written: it is 0 only by the power-on
  // fill. A file-level static likewise (line 3 col 17).
  EXPECT_EQ(warned("int g, x;\nmain() { x = 1; if (g) x = 2; }\n"), Strings{"2:21 uninitialized"});
  EXPECT_EQ(warned("static char s; int x;\nmain() { x = 1;\n  while (x) x = s; }\n"),
            Strings{"3:17 uninitialized"});
  // Written anywhere counts: in another function, in an interrupt handler,
  // by ++ or a compound assignment, by an initialiser.
  EXPECT_EQ(warned("int g, x;\nf() { g = 3; }\nmain() { x = g; f(); }\n"), Strings{});
  EXPECT_EQ(warned("#INT_VEC PIOA_VEC h\nint g, x;\ninterrupt reti h() { g = 1; }\n"
                   "main() { while (!g) x++; }\n"),
            Strings{});
  EXPECT_EQ(warned("int g, k, x;\nmain() { g++; k += 2; x = g + k; }\n"), Strings{});
  EXPECT_EQ(warned("int g = 5; int x;\nmain() { x = g; }\n"), Strings{});
  // Its address taken anywhere (a library routine or a pointer may write
  // it), in code or in another global's initialiser.
  EXPECT_EQ(warned("char buf[9]; char cc; int x;\nmain() { ser_send_z1(buf, &cc); x = cc; }\n"),
            Strings{});
  EXPECT_EQ(warned("int g, x;\nmain() { memset(&g, 1, 2); x = g; }\n"), Strings{});
  EXPECT_EQ(warned("int g; int *p = &g; int x;\nmain() { *p = 1; x = g; }\n"), Strings{});
  // Arrays are not checked (strcpy(buf, ...) writes through the decayed
  // pointer); the BIOS's timer variables are the BIOS's to write.
  EXPECT_EQ(warned("char buf[9]; int x;\nmain() { strcpy(buf, \"a\"); x = buf[0]; }\n"), Strings{});
  EXPECT_EQ(warned("unsigned long t;\nmain() { t = MS_TIMER; }\n"), Strings{});
  // Never read: nothing to warn about.
  EXPECT_EQ(warned("int g;\nmain() { }\n"), Strings{});
}

TEST(CompilerWarnings, UnreachableCode) {
  // "x = 2;" at line 2 col 18 ("main() { return; " is 17 bytes).
  EXPECT_EQ(warned("int x;\nmain() { return; x = 2; }\n"), Strings{"2:18 unreachable-code"});
  EXPECT_EQ(warned("int x;\nint f(int k) { switch (k) { case 1: return 1; break; case 2: x = 1; "
                   "} return 0; }\nmain() { f(1); }\n"),
            Strings{});
}

// The course's platform(): a send, then (or not) the delay loop.
const std::string kSend = "char buf[9]; char cc; int z;\n";
const std::string kPlatformNoDelay = "platform() { ser_send_z1(buf, &cc); }\n";
const std::string kPlatformDelay =
    "platform() { ser_send_z1(buf, &cc); for (z = 0; z < 700; z++); }\n";

TEST(CompilerWarnings, SendWithoutDelay) {
  // The second call, line 3 col 22.
  EXPECT_EQ(warned(kSend + kPlatformNoDelay + "main() { platform(); platform(); }\n"),
            Strings{"3:22 send-without-delay"});
  // Two sends in one function: the second at line 2 col 32 (9 + 21 + 1 bytes before it).
  EXPECT_EQ(warned(kSend + "main() { ser_send_z1(buf,&cc); ser_send_z1(buf,&cc); }\n"),
            Strings{"2:32 send-without-delay"});
  // A loop that sends every pass with nothing else: the call at col 20.
  EXPECT_EQ(warned(kSend + kPlatformNoDelay + "main() { while (1) platform(); }\n"),
            Strings{"3:20 send-without-delay"});
  // Delays between: inside platform(), or a delay loop at the call site.
  EXPECT_EQ(warned(kSend + kPlatformDelay + "main() { platform(); platform(); }\n"), Strings{});
  EXPECT_EQ(warned(kSend + kPlatformNoDelay +
                   "main() { while (1) { platform(); for (z = 0; z < 9; z++); } }\n"),
            Strings{});
}

// A declaration of a library routine must agree with it (the program
// tests/programs/library_declarations.dc shows the ones that do); "..." is
// for the library's printf only.
TEST(CompilerErrors, LibraryDeclarationsMustAgree) {
  const auto first = [](const std::string& source) {
    const auto r = compile(source, "l.dc");
    return r.errors.empty() ? std::string("<none>") : r.errors[0].format();
  };
  EXPECT_EQ(first("int strcpy();\nmain() { }\n")
                .rfind("l.dc:1:5: error: declaration of 'strcpy' does not agree with the library's "
                       "strcpy: returns a pointer, takes (a pointer, a pointer)",
                       0),
            0u);
  EXPECT_EQ(first("int printf(char *);\nmain() { }\n")
                .rfind("l.dc:1:5: error: declaration of 'printf' does not agree with the library's "
                       "printf: returns int, takes (a pointer, ...)",
                       0),
            0u);
  EXPECT_EQ(first("int f(int a, ...);\nmain() { }\n")
                .rfind("l.dc:1:14: error: variadic functions are not supported", 0),
            0u);
  EXPECT_EQ(first("int g(...);\nmain() { }\n")
                .rfind("l.dc:1:7: error: expected a named parameter before '...'", 0),
            0u);
}

// C89 (3.8.6): an unknown pragma is ignored; simbot says so.
TEST(CompilerWarnings, UnknownPragma) {
  EXPECT_EQ(warned("#pragma pack(1)\nmain() { }\n"), Strings{"1:1 unknown-pragma"});
}

// #if evaluates the operands C evaluates: a division by zero in the right
// operand of && is not done, one in an evaluated operand is an error.
// A member declaration that names no member declares nothing (gcc and
// clang warn likewise), at its first token: col 19 of "struct T { int I;
// int; };"; "B;" (a typedef of an untagged struct, line 2 col 12) and a
// tagged "struct U { int x; };" inside W (col 22), which declares U.
TEST(CompilerWarnings, MissingMemberName) {
  EXPECT_EQ(warned("struct T { int I; int; };\nstruct T t;\nmain() { t.I = 1; }\n"),
            Strings{"1:19 missing-member-name"});
  EXPECT_EQ(warned("typedef struct { int b; } B;\nstruct W { B; int c; struct U { int x; }; };\n"
                   "struct U u;\nmain() { u.x = sizeof(struct W); }\n"),
            (Strings{"2:12 missing-member-name", "2:22 missing-member-name"}));
}

TEST(CompilerErrors, IfDividesOnlyWhatItEvaluates) {
  EXPECT_TRUE(compile("#if 0 && 1 / 0\n#endif\nmain() { }\n", "i.dc").image);
  EXPECT_TRUE(compile("#if 1 ? 1 : 1 % 0\n#endif\nmain() { }\n", "i.dc").image);
  const auto r = compile("#if 1 && 1 / 0\n#endif\nmain() { }\n", "i.dc");
  expectError(r);
  EXPECT_EQ(r.errors[0].format().rfind("i.dc:1:12: error: division by zero in #if", 0), 0u)
      << r.errors[0].format();
}

TEST(CompilerWarnings, ImplicitFunctionDeclaration) {
  EXPECT_EQ(warned("main() { f(); }\nf() { }\n"), Strings{"1:10 implicit-function-declaration"});
  EXPECT_EQ(warned("int f();\nmain() { f(); }\nf() { }\n"), Strings{});
  EXPECT_EQ(warned("f() { }\nmain() { f(); }\n"), Strings{});
}

TEST(CompilerWarnings, DisabledAndWerror) {
  const std::string src = "int x;\nmain() { if (x = 5) x = 1; }\n";
  Options off;
  off.disabledWarnings.insert("parentheses");
  EXPECT_EQ(warned(src, off), Strings{});
  Options werror;
  werror.werror = true;
  Result r = compile(src, "e.dc", werror);
  EXPECT_FALSE(r.image.has_value());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].format().substr(0, r.errors[0].format().find('\n')),
            "e.dc:2:16: error: assignment used as a condition; write '==' to compare, or put the "
            "assignment in parentheses [-Werror=parentheses]");
  Result w = compile(src, "e.dc");
  ASSERT_EQ(w.warnings.size(), 1u);
  EXPECT_EQ(w.warnings[0].format().substr(0, w.warnings[0].format().find('\n')),
            "e.dc:2:16: warning: assignment used as a condition; write '==' to compare, or put "
            "the assignment in parentheses [-Wparentheses]");
}

TEST(CompilerWarnings, ReferenceProgramsWarnOnlyOfImplicitDeclarations) {
  for (const char* name : {"iceman.dc", "fig92.dc"}) {
    Result r = compile(readFile(fs::path(SIMBOT_SHARED_DIR) / "programs" / name), name);
    ASSERT_TRUE(r.image.has_value());
    for (const auto& d : r.warnings) EXPECT_EQ(d.warning, "implicit-function-declaration");
  }
}

// The shipped programs (programs/*.dc, what the quickstart and the README
// use) compile with no warning at all: prototypes before their calls, every
// global read assigned somewhere (issue 25).
TEST(CompilerWarnings, ShippedProgramsCompileWithoutWarnings) {
  int seen = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(SIMBOT_SOURCE_DIR) / "programs")) {
    if (entry.path().extension() != ".dc") continue;
    ++seen;
    const std::string name = entry.path().filename().string();
    Result r = simbot::compiler::compileFile(entry.path().string());
    ASSERT_TRUE(r.image.has_value()) << name;
    for (const auto& d : r.warnings) ADD_FAILURE() << name << ": " << d.format();
  }
  EXPECT_GE(seen, 4);
}
}  // namespace
