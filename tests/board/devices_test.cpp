// The board's devices: the serial port (double-buffered ASCI, Dynamic C's
// interrupt-driven send) with the plant's motor controller receiving its
// bytes (framing), and the Z80 PIO's port A in mode 3.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <optional>

#include "board/pio.h"
#include "board/serial_port.h"
#include "plant/motor_receiver.h"

using namespace simbot::board;
using simbot::plant::MotorReceiver;
using simbot::plant::ReceivedFrame;

namespace {

class TestMemory : public Memory {
 public:
  std::array<uint8_t, 65536> bytes{};
  uint8_t read8(uint16_t a) const override { return bytes[a]; }
  void write8(uint16_t a, uint8_t v) override { bytes[a] = v; }
  void put(uint16_t a, const char* s) { std::memcpy(&bytes[a], s, std::strlen(s) + 1); }
};

constexpr uint16_t kBuf = 0x200, kCc = 0x300;

// Drives a link with an ISR that runs `latency` ticks after each request.
struct Driver {
  SerialPort link;
  MotorReceiver receiver;
  TestMemory mem;
  std::vector<std::pair<Tick, ReceivedFrame>> frames;
  Tick latency = 50;
  bool interruptsEnabled = true;

  std::optional<OverwrittenSend> send(Tick t0, const char* text, uint8_t count) {
    mem.put(kBuf, text);
    mem.bytes[kCc] = count;
    return link.send(t0, kBuf, kCc, mem);
  }
  // Runs until `end`, servicing requests and finishing bytes in tick order.
  void runUntil(Tick end, Tick from) {
    Tick t = from;
    while (t <= end) {
      if (interruptsEnabled && link.requestingInterrupt()) {
        t += latency;
        link.service(t, mem);
        continue;
      }
      auto done = link.nextByteDone();
      if (!done || *done > end) break;
      t = *done;
      if (auto f = receiver.receive(*link.byteDone(t))) frames.emplace_back(t, *f);
    }
  }
};

TEST(SerialPort, PlatformLatchesNineCharactersAfterT0) {
  Driver d;
  d.send(1000, "4fgr4rgr", 9);
  d.runUntil(1'000'000, 1000);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_EQ(d.frames[0].first, 1000 + 9 * 9600);
  EXPECT_TRUE(d.frames[0].second.command.has_value());
  EXPECT_EQ(d.frames[0].second.bytes, "4fgr4rgr");
  EXPECT_EQ(d.frames[0].second.command->left.speed, 4);
  EXPECT_TRUE(d.frames[0].second.command->left.forward);
  EXPECT_FALSE(d.frames[0].second.command->right.forward);
  EXPECT_EQ(d.mem.bytes[kCc], 0);
}

TEST(SerialPort, SecondSendMidwayWinsAndFirstIsNeverLatched) {
  Driver d;
  d.send(0, "4fgr4rgr", 9);
  d.runUntil(3 * 9600 + 100, 0);  // three bytes out, one in the TSR, one in TDR
  const auto overwritten = d.send(3 * 9600 + 200, "cfgrcfgr", 9);
  // The library had fetched bytes 0..4 of the first (three out, one
  // shifting, one in the TDR) and had four to go: that send is overwritten.
  ASSERT_TRUE(overwritten.has_value());
  EXPECT_EQ(overwritten->sentAt, 0);
  EXPECT_EQ(overwritten->count, 9);
  EXPECT_EQ(overwritten->fetched, 5);
  d.runUntil(2'000'000, 3 * 9600 + 200);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_TRUE(d.frames[0].second.command.has_value());
  EXPECT_EQ(d.frames[0].second.bytes, "cfgrcfgr");
  // Bytes 0..4 of the first string went out (shift and data registers), then
  // all nine of the second: 14 characters from T0.
  EXPECT_EQ(d.frames[0].first, 14 * 9600);
}

// Byte k > 0 of a send at 0 is fetched by the interrupt 50 ticks after
// the TDR empties, at (k - 1) x 9600 + 50: byte 7 at 57,650, byte 8 (the
// NUL, the last) at 67,250. A send at 67,190 finds one byte unfetched and
// overwrites the first send; one at 67,260 finds none and does not, though
// bytes 7 and 8 are still in the port (they go out, then the new frame).
TEST(SerialPort, ASendOverwritesOnlyWhileTheLibraryHasBytesToFetch) {
  for (const Tick at : {Tick{67'190}, Tick{67'260}}) {
    Driver d;
    EXPECT_FALSE(d.send(0, "4fgr4rgr", 9).has_value());
    d.runUntil(at - 1, 0);
    const auto overwritten = d.send(at, "cfgrcfgr", 9);
    d.runUntil(2'000'000, at);
    if (at < 67'250) {
      ASSERT_TRUE(overwritten.has_value()) << at;
      EXPECT_EQ(overwritten->fetched, 8);
      ASSERT_EQ(d.frames.size(), 1u);  // "4fgr4rgr", then the new frame: one NUL
      EXPECT_EQ(d.frames[0].second.bytes, "cfgrcfgr");
    } else {
      EXPECT_FALSE(overwritten.has_value()) << at;
      ASSERT_EQ(d.frames.size(), 2u);
      EXPECT_EQ(d.frames[0].second.bytes, "4fgr4rgr");
      EXPECT_EQ(d.frames[1].second.bytes, "cfgrcfgr");
    }
  }
}

TEST(SerialPort, StrcpyIntoBufferDuringSendChangesTheFrame) {
  Driver d;
  d.send(0, "4fgr4rgr", 9);
  d.runUntil(2 * 9600 + 10, 0);
  std::memcpy(&d.mem.bytes[kBuf], "cfgrcfgr", 8);  // strcpy halfway through
  d.runUntil(2'000'000, 2 * 9600 + 10);
  ASSERT_EQ(d.frames.size(), 1u);
  // Bytes 0..3 were fetched already (shift, data register, ISR ahead).
  EXPECT_EQ(d.frames[0].second.bytes, "4fgrcfgr");
  EXPECT_TRUE(d.frames[0].second.command.has_value());
}

TEST(SerialPort, SendStallsWhileInterruptsAreOffAndResumes) {
  Driver d;
  d.interruptsEnabled = false;
  d.send(0, "4fgr4rgr", 9);
  d.runUntil(1'000'000, 0);
  EXPECT_TRUE(d.frames.empty());
  EXPECT_EQ(d.link.bytesSent(), 1u);  // only the byte the call itself loaded
  EXPECT_TRUE(d.link.idle());
  d.interruptsEnabled = true;  // EI at tick 1,000,000
  d.runUntil(3'000'000, 1'000'000);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_EQ(d.frames[0].second.bytes, "4fgr4rgr");
  EXPECT_EQ(d.frames[0].first, 1'000'000 + d.latency + 8 * 9600);
}

TEST(SerialPort, ShortOrInvalidFramesAreRejected) {
  Driver d;
  d.send(0, "4fgr", 5);
  d.runUntil(1'000'000, 0);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_FALSE(d.frames[0].second.command.has_value());
  d.send(2'000'000, "4fxr4rgr", 9);
  d.runUntil(3'000'000, 2'000'000);
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_FALSE(d.frames[1].second.command.has_value());
}

// ICEMAN's set-up of port A.
Pio icemanPort() {
  Pio p;
  for (uint8_t w : {0xff, 0xff, 0x10, 0x97, 0xfc, 0x87}) p.control(w);
  return p;
}

TEST(Pio, IcemanSetupRequestsOnFallingDetector) {
  Pio p = icemanPort();
  EXPECT_EQ(p.mode(), 3);
  EXPECT_EQ(p.vector(), 0x10);
  EXPECT_TRUE(p.interruptEnabled());
  EXPECT_FALSE(p.setInputs(0xFF));
  EXPECT_TRUE(p.setInputs(0xFD));  // fore detector low: condition true
  EXPECT_EQ(p.read(), 253);
  EXPECT_FALSE(p.setInputs(0xFC));  // still true: no new request
  EXPECT_FALSE(p.setInputs(0xFF));
  EXPECT_TRUE(p.setInputs(0xFE));  // aft
}

struct PioCase {
  uint8_t icw, mask;
  uint8_t lines;
  bool request;
};

TEST(Pio, ControlWordMatrix) {
  const PioCase cases[] = {
      {0x97, 0xfc, 0xFD, true},   // OR, active low, bit 1 low
      {0x97, 0xfc, 0xFB, false},  // OR, active low, a masked bit low
      {0xD7, 0xfc, 0xFD, false},  // AND, active low, only one of two low
      {0xD7, 0xfc, 0xFC, true},   // AND, active low, both low
      {0xB7, 0xfc, 0x01, false},  // OR, active high: from all-low lines...
      {0x17, 0xfc, 0xFD, false},  // interrupts disabled in the control word
  };
  for (const auto& c : cases) {
    Pio p;
    for (uint8_t w : {0xff, 0xff, 0x10}) p.control(w);
    p.control(c.icw);
    p.control(c.mask);
    p.setInputs(0xFF);
    EXPECT_EQ(p.setInputs(c.lines), c.request)
        << std::hex << "icw " << int(c.icw) << " lines " << int(c.lines);
  }
  // Active high: a monitored bit rising from low makes the condition true.
  Pio p;
  for (uint8_t w : {0xff, 0xff, 0x10, 0xB7, 0xfc}) p.control(w);
  EXPECT_FALSE(p.setInputs(0x00));
  EXPECT_TRUE(p.setInputs(0x02));
}

TEST(Pio, NoRequestWhileUnderServiceHeldUntilReti) {
  Pio p = icemanPort();
  EXPECT_TRUE(p.setInputs(0xFD));
  p.accepted();
  EXPECT_FALSE(p.setInputs(0xFF));
  EXPECT_FALSE(p.setInputs(0xFE));  // becomes true while in service: held
  EXPECT_TRUE(p.returned());        // raised at RETI
  EXPECT_FALSE(p.returned());
}

TEST(Pio, UnarmedPortNeverRequests) {
  Pio p;  // fig92 never programs port A
  EXPECT_FALSE(p.setInputs(0xFF));
  EXPECT_FALSE(p.setInputs(0xFD));
  EXPECT_FALSE(p.setInputs(0xFC));
}

}  // namespace
