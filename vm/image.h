// A compiled program: what the compiler produces and the VM loads.
// Code bytes with a parallel line table (one source line per code byte, as in
// craftinginterpreters' chunk.h), the initial contents of robot memory, the
// interrupt vector table and the symbol table.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace simbot::vm {

// Robot memory map (64 KiB, 16-bit addresses). Documented in docs/cycle-model.md.
inline constexpr uint32_t kMemorySize = 0x10000;
inline constexpr uint16_t kNullPageEnd = 0x0100;  // 0x0000-0x00FF: access faults
inline constexpr uint16_t kDataBase = 0x0100;     // globals and statics from here
inline constexpr uint16_t kStackTop = 0xFFFF;     // auto frames grow down from here

// Port addresses of the Tiny Giant's I/O bus that programs name without
// declaring them (assumption: the thesis gives no addresses).
inline constexpr uint16_t kPortPIODA = 0x48;
inline constexpr uint16_t kPortPIODB = 0x49;
inline constexpr uint16_t kPortPIOCA = 0x4A;
inline constexpr uint16_t kPortPIOCB = 0x4B;
inline constexpr uint16_t kPortENB485 = 0xC0;
// Interrupt vector names (IM2 vector bytes a program writes to the PIO).
inline constexpr uint8_t kVecPIOA = 0x10;

// The Z180's PRT0 as Dynamic C's BIOS sets it: the 9.216 MHz clock divided
// by 20 (the PRT prescaler) and a reload of 450 gives the 1,024 Hz tick.
inline constexpr uint32_t kPrtPrescale = 20;
inline constexpr uint32_t kPrtReload = 450;
inline constexpr uint32_t kPrtTicks = kPrtPrescale * kPrtReload;  // 9,000 ticks a period
inline constexpr uint32_t kTimerHz = 1024;

// Dynamic C's CoData (User's Manual 5.4.1), one per costatement, laid out as
// that manual draws it: CSState, lastlocADDR, lastlocCBR, ChkSum (XOR of the
// three address bytes), firsttime, content (the Delay functions' start),
// ChkSum2. lastlocADDR 0 means "from the top".
inline constexpr uint16_t kCoState = 0;
inline constexpr uint16_t kCoLastLoc = 1;
inline constexpr uint16_t kCoLastLocCbr = 3;
inline constexpr uint16_t kCoChkSum = 4;
inline constexpr uint16_t kCoFirstTime = 5;
inline constexpr uint16_t kCoContent = 6;
inline constexpr uint16_t kCoChkSum2 = 10;
inline constexpr uint16_t kCoDataSize = 11;
// CSState flags (User's Manual Table 5-1): STOPPED and INIT both set is
// "done" (or reset); STOPPED alone is paused; INIT alone is initialised to
// run; neither is running.
inline constexpr uint8_t kCoStopped = 0x01;
inline constexpr uint8_t kCoInit = 0x02;

// Where the BIOS timer service keeps its counters: TICK_TIMER, MS_TIMER and
// SEC_TIMER (unsigned long each) and the service's millisecond fraction
// byte. All zero when the program does not use the timer library.
struct TimerBlock {
  uint16_t tick = 0;
  uint16_t ms = 0;
  uint16_t sec = 0;
  uint16_t msFraction = 0;
  bool used() const { return tick != 0; }
};

struct VectorBinding {
  uint8_t vector;    // IM2 vector byte
  uint16_t handler;  // code address of the interrupt reti function
  std::string handlerName;
};

struct Symbol {
  enum class Kind : uint8_t { Function, Handler, Global, Static, Auto, Param };
  // What the memory of a data symbol holds, as a reader of it (--watch)
  // must take it: one of the scalars (Dynamic C's char is unsigned, int 16
  // bits, long 32, float IEEE single, pointers 16), or an aggregate (array,
  // struct, union); a function's is Code.
  enum class Value : uint8_t {
    Char,
    Int,
    UInt,
    Long,
    ULong,
    Float,
    Pointer,
    Aggregate,
    Code,
    SChar
  };
  std::string name;  // for statics and autos: "function.name"
  Kind kind;
  uint32_t address;  // code address (functions), memory address (data),
                     // frame offset (autos)
  uint32_t size;     // bytes (data) or code bytes (functions)
  std::string type;  // C type for people, e.g. "unsigned long", "struct pt *"
  Value value;
  int line;
  // The data's type in Image::types (-1: none, a function's); for an auto
  // or parameter, the last line of the block it is declared in (it is in
  // scope from `line` to there).
  int32_t typeId = -1;
  int scopeEnd = 0;
  bool parameter = false;  // a function's parameter (Auto in #class auto, else Param)
};

// A data type, for readers that take memory apart (the debugger's print,
// --watch): scalars as Symbol::Value reads them, pointers, arrays, structs
// and unions with their members' offsets. Indices refer to Image::types.
struct TypeInfo {
  enum class Kind : uint8_t { Void, Scalar, Pointer, Array, Struct, Union, Function };
  Kind kind = Kind::Void;
  Symbol::Value scalar = Symbol::Value::Aggregate;  // Scalar and Pointer
  uint32_t size = 0;
  int32_t base = -1;  // Pointer: pointee; Array: element; Function: return
  int32_t count = 0;  // Array: elements (0: unknown, "[]")
  std::string name;   // as C spells it: "struct pt", "char[8]"
  struct Field {
    std::string name;
    uint32_t offset;
    int32_t type;
  };
  std::vector<Field> fields;  // Struct, Union
};

struct Image {
  std::string sourceName;
  std::vector<std::string> sourceLines;  // for the disassembly
  std::vector<uint8_t> code;
  std::vector<int32_t> lines;  // source line of each code byte (1-based)
  uint16_t entry = 0;          // code address of main
  // Initial memory: bytes [kDataBase, kDataBase + data.size()) hold the
  // globals' and statics' initial values (zeros where not initialised).
  std::vector<uint8_t> data;
  // Parallel to data: 1 where the program gives the byte a value at load
  // (globals and statics with an initialiser, string literals). The others
  // hold whatever the RAM held at power-on (Vm::fillMemory).
  std::vector<uint8_t> initialised;
  std::vector<VectorBinding> vectors;
  std::vector<Symbol> symbols;
  std::vector<TypeInfo> types;  // Symbol::typeId
  TimerBlock timer;
  // Code addresses a costatement may resume at (yield and waitfor points),
  // sorted: a lastlocADDR that is not one of them is a fault.
  std::vector<uint16_t> resumePoints;
  // Delay loops the compiler marked for fast-forward (DESIGN.md, issue 13):
  // `for (v = ...; v < N; v++) ;` on a static or global integer, whose code
  // is top: LDGW v; PUSHW N; LTW|LTUW|LEW|LEUW; JZ exit; [DBG]; INCGW v;
  // JMP top; exit: (or the 32-bit LDGL, PUSHL, LTL..LEUL, INCGL). The VM
  // checks that shape before trusting a mark.
  struct DelayLoop {
    uint16_t top;
    uint16_t exit;
  };
  std::vector<DelayLoop> delayLoops;
  // The functions a call through a pointer (CALLI) may reach, by address:
  // each one's first instruction and the arguments its prologue pops.
  // Interrupt handlers are not among them.
  struct Entry {
    uint16_t address;
    uint8_t params;
  };
  std::vector<Entry> entries;
  const Entry* entryAt(uint32_t codeAddress) const;  // null: no function starts there
  // First code address of each function, for profiles and fault messages.
  const Symbol* functionAt(uint32_t codeAddress) const;
  int lineAt(uint32_t codeAddress) const {
    return codeAddress < lines.size() ? lines[codeAddress] : 0;
  }
  // Per code address, for a RET: the size of the #class auto frame that
  // its function's ENTER made (the epilogue pops IX from just above it, and
  // the return address from above that), or -1: a static function's RET,
  // or no RET. A function starts at a function symbol, a CALL's target or
  // an interrupt handler; its frame is its first instruction's, if ENTER.
  std::vector<int32_t> returnFrames() const;
  // The head of the loop written on source line N: the target of a
  // backward jump whose jump and target both belong to line N (the
  // outermost such loop when there are several: the lowest target). It
  // runs once per pass, and once more for the test that ends the loop.
  // None: no loop lies on line N (or the code cannot be walked).
  std::optional<uint32_t> loopHead(int line) const;
};

}  // namespace simbot::vm
