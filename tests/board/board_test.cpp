// The board as a value: a copy taken mid-run goes on as the original (the
// VM, the serial port and library, the PIO, the streams, the counters), a
// restore replays the run, and a reset is the controller's: the VM as
// powered on then, the port idle, the PIO unarmed, the rest carried on.
// The host here is the least that runs a board: fixed eyes, the bytes
// received by the plant's motor controller, an edge line that falls at a
// fixed tick.
#include "board/board.h"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "plant/motor_receiver.h"
#include "tests/support/test_host.h"
#include "vm/bytecode.h"

using namespace simbot;
using board::Board;
using vm::Tick;

namespace {

constexpr Tick kSecond = vm::kTicksPerSecond;

const board::StreamSeeds kSeeds{1, 2, 3, 4, 5};
board::Settings settingsWithRandomMemory() {
  board::Settings s;
  s.randomMemory = true;
  return s;
}
const board::Settings kSettings = settingsWithRandomMemory();

// Runs a board: its VM's bus, the receiver at the wire's far end.
class Host : public vm::Bus {
 public:
  Board* board = nullptr;
  plant::MotorReceiver receiver;
  std::vector<std::pair<Tick, std::string>> frames;
  std::vector<std::pair<Tick, int>> overwritten;
  std::vector<std::pair<Tick, uint8_t>> outs;
  Tick edgeAt = 6 * kSecond;  // the fore detector's line falls here

  int adSample(Tick, int channel) override {
    return channel == 0 ? 40 + static_cast<int>(board->eyeNoise.next() % 3) : 30;
  }
  // The board decodes its ports (port B and ENB485 are the host's: kept
  // here with every other write).
  void out(Tick t, uint16_t port, uint8_t value) override {
    board->out(port, value);
    outs.emplace_back(t, value);
  }
  uint8_t in(Tick, uint16_t port) override { return board->in(port); }
  // Each changes when the next byte is done: runUntil looks again.
  void serialSend(Tick t, uint16_t buf, uint16_t cc) override {
    if (const auto o = board->serialSend(t, buf, cc)) overwritten.emplace_back(t, o->fetched);
    board->cpu.stopAtNextBoundary();
  }
  void serialTxService(Tick t, vm::Vm&) override {
    board->serialService(t);
    board->cpu.stopAtNextBoundary();
  }
  void interruptAccepted(Tick, vm::Irq irq, uint32_t) override {
    ++board->interruptCounts[static_cast<size_t>(irq)];
    if (irq == vm::Irq::Pio) board->pio.accepted();
  }
  void interruptReturned(Tick, vm::Irq irq) override {
    if (irq == vm::Irq::Pio) board->pioReturned();
  }

  // Runs to `end`: each byte's stop bit and the edge at their ticks.
  void runUntil(Tick end) {
    while (board->cpu.now() < end && !board->cpu.fault()) {
      Tick horizon = end;
      if (const auto done = board->serial.nextByteDone()) horizon = std::min(horizon, *done);
      if (edgeAt > board->cpu.now()) horizon = std::min(horizon, edgeAt);
      board->cpu.run(horizon);
      const Tick now = board->cpu.now();
      if (now >= edgeAt && board->plantLow == 0) {
        board->plantLow = 0x02;
        board->updateEdgeLines();
      }
      if (const auto done = board->serial.nextByteDone(); done && *done <= now)
        if (const auto frame = receiver.receive(*board->serialByteDone(*done)))
          frames.emplace_back(*done, frame->bytes);
    }
  }
};

// A board and its host.
struct Robot {
  Host host;
  Board board;
  Robot(const vm::Image& image, const Robot* from = nullptr)
      : host(from ? from->host : Host{}),
        board(from ? Board(from->board, host)
                   : Board(image, host, testkit::calibratedCosts(), kSeeds, kSettings)) {
    host.board = &board;
  }
};

TEST(BoardSnapshot, ACopyGoesOnAsTheOriginalAndARestoreReplaysIt) {
  const vm::Image image = testkit::compileFileOrDie(SIMBOT_SHARED_DIR "/programs/iceman.dc");
  Robot run(image);
  // ICEMAN waits 50,000 passes of a long loop before its first frame.
  run.host.runUntil(4 * kSecond);
  ASSERT_EQ(run.board.cpu.fault(), nullptr);

  Robot saved(image, &run);
  EXPECT_TRUE(saved.board == run.board);
  Robot copy(image, &run);
  run.host.runUntil(8 * kSecond);
  copy.host.runUntil(8 * kSecond);
  EXPECT_TRUE(copy.board == run.board);
  EXPECT_EQ(copy.host.frames, run.host.frames);
  EXPECT_EQ(copy.host.outs, run.host.outs);
  // Past the snapshot the edge fell, ICEMAN's handler ran, frames went out.
  EXPECT_FALSE(saved.board == run.board);
  EXPECT_GT(run.board.interruptCounts[static_cast<size_t>(vm::Irq::Pio)], 0u);
  EXPECT_GT(run.host.frames.size(), saved.host.frames.size());

  const Host firstRun = run.host;
  run.board = saved.board;
  run.host = saved.host;
  run.host.board = &run.board;
  EXPECT_TRUE(run.board == saved.board);
  run.host.runUntil(8 * kSecond);
  EXPECT_TRUE(run.board == copy.board);
  EXPECT_EQ(run.host.frames, firstRun.frames);
  EXPECT_EQ(run.host.outs, firstRun.outs);
}

TEST(BoardReset, IsTheControllersResetAndCarriesTheRestOn) {
  const vm::Image image = testkit::compileFileOrDie(SIMBOT_SHARED_DIR "/programs/iceman.dc");
  Robot run(image);
  run.host.edgeAt = kSecond / 2;
  run.host.runUntil(3 * kSecond);
  // Let the port drain: a reset needs it idle (the scheduler's reload delay).
  while (!run.board.serial.idle()) run.host.runUntil(run.board.cpu.now() + 9600);
  ASSERT_TRUE(run.board.pio.interruptEnabled());  // ICEMAN armed port A
  // The last eye values read, as a host that traces them keeps them.
  run.board.lastAdValue = {41, 30};
  const Board before(run.board, run.host);
  const Tick t = run.board.cpu.now();

  run.board.reset(t);
  EXPECT_EQ(run.board.serial, board::SerialPort{});
  EXPECT_FALSE(run.board.pio.interruptEnabled());
  EXPECT_EQ(run.board.enb485, -1);
  // The reloaded program has read no eye yet (its first reading is traced).
  EXPECT_EQ(run.board.lastAdValue, (std::array<int, 2>{-1, -1}));
  // The lines at the pins, the streams and the counters go on.
  EXPECT_EQ(run.board.edgeLines, before.edgeLines);
  EXPECT_EQ(run.board.eyeNoise, before.eyeNoise);
  EXPECT_EQ(run.board.interruptCounts, before.interruptCounts);
  EXPECT_EQ(run.board.cpu.stats().instructions, before.cpu.stats().instructions);
  // The VM is one powered on at t with RAM from the stream's next bytes.
  Host freshHost;
  vm::Vm fresh(image, freshHost, testkit::calibratedCosts(), t);
  plant::SplitMix64 fill = before.memoryFill;
  fresh.fillMemory([&] { return fill.next(); });
  EXPECT_TRUE(run.board.cpu.sameMachine(fresh));
  EXPECT_EQ(run.board.memoryFill, fill);
}

// The ports as the Tiny Giant decodes them (vm/image.h): the PIO's control
// and data ports are the board's, port B (the guns and solenoids) and
// ENB485 (when it changes) go on to the host, a read of no device is 0xFF.
TEST(BoardPorts, TheBoardDecodesItsOwnPorts) {
  const vm::Image image = testkit::compileFileOrDie(SIMBOT_SHARED_DIR "/programs/iceman.dc");
  Robot r(image);
  Board& b = r.board;
  // Z80 PIO manual: 0xCF selects mode 3, the next word is the direction
  // register (1 = input).
  EXPECT_EQ(b.out(vm::kPortPIOCA, 0xCF), board::PortWrite::Done);
  EXPECT_EQ(b.out(vm::kPortPIOCA, 0x03), board::PortWrite::Done);
  EXPECT_EQ(b.pio.mode(), 3);
  EXPECT_EQ(b.out(vm::kPortPIODA, 0xA0), board::PortWrite::Done);
  // Bits 7-2 are outputs (the latch), 1-0 inputs (the lines, high).
  EXPECT_EQ(b.in(vm::kPortPIODA), 0xA3);
  EXPECT_EQ(b.out(vm::kPortPIODB, 0x12), board::PortWrite::PortB);
  EXPECT_EQ(b.out(vm::kPortENB485, 1), board::PortWrite::Enb485);
  EXPECT_EQ(b.out(vm::kPortENB485, 1), board::PortWrite::Done);
  EXPECT_EQ(b.out(vm::kPortENB485, 0), board::PortWrite::Enb485);
  EXPECT_EQ(b.enb485, 0);
  EXPECT_EQ(b.out(0x1234, 0x55), board::PortWrite::Done);
  EXPECT_EQ(b.in(0x1234), 0xFF);
  EXPECT_EQ(b.in(vm::kPortPIODB), 0xFF);
}

}  // namespace
