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

vm::CostTable costsFor(const vm::CostTable& match, const Settings& settings) {
  vm::CostTable table = match;
  if (settings.cpu != match.knobs.cpu) {
    vm::CostKnobs knobs = match.knobs;
    knobs.cpu = settings.cpu;
    table = vm::makeCostTable(knobs);
  }
  table.knobs.timerService = settings.timerService;
  table.knobs.fastForward = match.knobs.fastForward && settings.fastForward;
  return table;
}

Board::Board(const vm::Image& image, vm::Bus& bus, const vm::CostTable& matchCosts,
             const StreamSeeds& seeds, const Settings& boardSettings)
    : Devices(seeds, boardSettings), cpu(image, bus, costsFor(matchCosts, boardSettings)) {
  fillMemory();
}

PortWrite Board::out(uint16_t port, uint8_t value) {
  switch (port) {
    case vm::kPortPIOCA:
      pio.control(value);
      return PortWrite::Done;
    case vm::kPortPIODA:
      pio.writeData(value);
      return PortWrite::Done;
    case vm::kPortPIODB:
      return PortWrite::PortB;
    case vm::kPortENB485: {
      const bool changed = value != enb485;
      enb485 = value;
      return changed ? PortWrite::Enb485 : PortWrite::Done;
    }
    default:
      return PortWrite::Done;  // PIOCB set-up and unknown ports have no effect here
  }
}

uint8_t Board::in(uint16_t port) const { return port == vm::kPortPIODA ? pio.read() : 0xFF; }

void Board::reset(Tick t) {
  if (!serial.idle()) throw std::logic_error("a reset with bytes still in the serial port");
  cpu.reset(t);
  fillMemory();
  serial = SerialPort{};
  pio = Pio{};
  // The reset PIO sees the lines as they are; unarmed, it raises nothing.
  if (pio.setInputs(edgeLines)) throw std::logic_error("an unarmed PIO raised an interrupt");
  enb485 = -1;
  // The reloaded program has read nothing: its first reading of each eye is
  // traced even if the faulted program's last was the same.
  lastAdValue = {-1, -1};
}

void Board::fillMemory() {
  if (settings.randomMemory) cpu.fillMemory([this] { return memoryFill.next(); });
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
