// board/board.cpp -- the board as a value (board.h).
#include "board/board.h"

#include <stdexcept>

namespace simbot::board {

namespace {

// The serial library reads and writes the program's memory.
class CpuMemory final : public Memory {
 public:
  explicit CpuMemory(vm::Vm& cpu) : cpu_(cpu) {}
  uint8_t read8(uint16_t address) const override { return cpu_.read8(address); }
  void write8(uint16_t address, uint8_t value) override { cpu_.write8(address, value); }

 private:
  vm::Vm& cpu_;
};

}  // namespace

Board::Board(const vm::Image& image, vm::Bus& bus, const vm::CostTable& costs,
             const StreamSeeds& seeds, bool randomMemoryFill)
    : Devices(seeds, randomMemoryFill), cpu(image, bus, costs) {
  fillMemory();
}

void Board::reset(Tick t) {
  if (!serial.idle()) throw std::logic_error("a reset with bytes still in the serial port");
  cpu.reset(t);
  fillMemory();
  serial = SerialPort{};
  pio = Pio{};
  // The reset PIO sees the lines as they are; unarmed, it raises nothing.
  if (pio.setInputs(edgeLines)) throw std::logic_error("an unarmed PIO raised an interrupt");
  enb485 = -1;
}

void Board::fillMemory() {
  if (randomMemory) cpu.fillMemory([this] { return memoryFill.next(); });
}

std::optional<OverwrittenSend> Board::serialSend(Tick t, uint16_t buf, uint16_t ccAddress) {
  CpuMemory memory(cpu);
  auto overwritten = serial.send(t, buf, ccAddress, memory);
  updateSerialRequest();
  return overwritten;
}

void Board::serialService(Tick t) {
  CpuMemory memory(cpu);
  serial.service(t, memory);
  updateSerialRequest();
}

std::optional<uint8_t> Board::serialByteDone(Tick t) {
  auto byte = serial.byteDone(t);
  updateSerialRequest();
  return byte;
}

void Board::updateSerialRequest() {
  if (serial.requestingInterrupt())
    cpu.request(vm::Irq::SerialTx);
  else
    cpu.cancelRequest(vm::Irq::SerialTx);
}

bool Board::updateEdgeLines() {
  const auto lines = static_cast<uint8_t>(~(plantLow | injectedLow));
  const bool changed = lines != edgeLines;
  edgeLines = lines;
  if (pio.setInputs(edgeLines)) cpu.request(vm::Irq::Pio, pio.vector());
  return changed;
}

void Board::pioReturned() {
  if (pio.returned()) cpu.request(vm::Irq::Pio, pio.vector());
}

}  // namespace simbot::board
