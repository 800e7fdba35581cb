// board/board.h -- the robot's controller board, a Z-World Tiny Giant, as
// one value: everything on it that changes while the program runs.
//
// The Z180 running the program (vm::Vm: registers, memory, stacks and
// frames, pending requests, PRT0), its ASCI channel 1 with Dynamic C's
// serial library (SerialPort), the PIO's port A (Pio) and the lines at its
// pins, the RS-485 enable, the random streams of the robot's devices and
// the run's counters. The constant parts, the program image and the
// robot's specification, are not in it (as MuJoCo keeps mjModel apart from
// mjData); the motor controller's receiver and the physics are the
// plant's. The host (the scheduler) implements the VM's bus: it turns the
// board's accesses into plant inputs, queued events and trace records.
//
// A Board is a value apart from that bus: Board(other, bus) is a copy of
// all of it that talks to `bus`, restore() takes a copy back, and a copy
// goes on byte for byte as the original would. reset() is the controller's
// reset (a reload).
#pragma once
#include <array>
#include <cstdint>
#include <optional>

#include "board/pio.h"
#include "board/serial_port.h"
#include "plant/plant.h"
#include "vm/vm.h"

namespace simbot::board {

// The seeds of the robot's random streams, one per purpose.
struct StreamSeeds {
  uint64_t memoryFill;  // power-on RAM (profile random_memory)
  uint64_t eyeNoise;    // the A/D's reading of the eyes
  uint64_t gunLuck;     // jams and misfires
  uint64_t muzzle;      // muzzle-speed spread, one draw per launching stroke
  uint64_t dispersion;  // the ball's azimuth and elevation, two draws per launching stroke
};

// Everything on the board but the Z180: a plain value.
struct Devices {
  explicit Devices(const StreamSeeds& seeds, bool randomMemoryFill)
      : memoryFill(seeds.memoryFill),
        eyeNoise(seeds.eyeNoise),
        gunLuck(seeds.gunLuck),
        muzzle(seeds.muzzle),
        dispersion(seeds.dispersion),
        randomMemory(randomMemoryFill) {}
  bool operator==(const Devices&) const = default;

  SerialPort serial;
  Pio pio;
  // Port A's edge lines (bit 1 fore, bit 0 aft): low while the plant's
  // detector or an injection holds them.
  uint8_t plantLow = 0, injectedLow = 0;
  uint8_t edgeLines = 0xFF;
  int enb485 = -1;  // never written
  plant::SplitMix64 memoryFill, eyeNoise, gunLuck, muzzle, dispersion;
  bool randomMemory;
  // Over the whole run: ad_rd8 calls per eye and the last value each
  // returned, interrupts accepted per source (vm::Irq).
  std::array<int64_t, 2> adReads{};
  std::array<int, 2> lastAdValue{-1, -1};
  std::array<uint64_t, vm::kIrqCount> interruptCounts{};
};

class Board : public Devices {
 public:
  // Powered on at tick 0; `randomMemory` fills RAM from its stream.
  Board(const vm::Image& image, vm::Bus& bus, const vm::CostTable& costs, const StreamSeeds& seeds,
        bool randomMemory);
  Board(const Board& other, vm::Bus& bus) : Devices(other), cpu(other.cpu, bus) {}
  Board(const Board&) = delete;
  Board& operator=(const Board&) = delete;
  // This board takes `snapshot`'s state; its VM keeps talking to its bus.
  void restore(const Board& snapshot) {
    static_cast<Devices&>(*this) = snapshot;
    cpu.restore(snapshot.cpu);
  }
  // The controller's reset at t: the Z180 as powered on at t (its RAM
  // filled from the next bytes of its stream, as a power cycle leaves new
  // garbage), the serial port and library idle, the PIO unarmed (it raises
  // nothing until the program arms it again), ENB485 unknown. The lines at
  // the pins, the streams and the counters go on. The port must be idle.
  void reset(Tick t);
  bool operator==(const Board& other) const {
    return cpu == other.cpu && Devices::operator==(other);
  }

  // The serial library: ser_send_z1 returned at t (the send it overwrote,
  // if any), its transmit interrupt service ran at t, the TSR finished a
  // byte at t (the byte). Each leaves the transmit request as the port
  // asks.
  std::optional<OverwrittenSend> serialSend(Tick t, uint16_t buf, uint16_t ccAddress);
  void serialService(Tick t);
  std::optional<uint8_t> serialByteDone(Tick t);
  // Port A's pins after plantLow or injectedLow changed: whether they
  // changed; the PIO's request, if it makes one, is raised.
  bool updateEdgeLines();
  // The PIO's interrupt returned: a condition held meanwhile is raised.
  void pioReturned();

  vm::Vm cpu;

 private:
  void fillMemory();
  void updateSerialRequest();
};

}  // namespace simbot::board
