// board/board.h -- the robot's controller board, a Z-World Tiny Giant, as
// one value: everything on it that changes while the program runs.
//
// The Z180 running the program (vm::Vm: registers, memory, stacks and
// frames, pending requests, PRT0), its ASCI channel 1 with Dynamic C's
// serial library (SerialPort), the PIO's port A (Pio) and the lines at its
// pins, the RS-485 enable, the random streams of the robot's devices and
// the run's counters. The constant parts, the program (image, cost table,
// decode tables: vm/program.h, shared by every copy) and the robot's
// specification, are not copied with it (as MuJoCo keeps mjModel apart
// from mjData); the motor controller's receiver and the physics are the
// plant's. The board decodes its own I/O ports (out, in), owns its
// settings (Settings: the profile's [controller]) and its reset. The host
// (the scheduler) implements the VM's bus: it turns what the board hands
// on (port B, ENB485, the serial library's bytes) into plant inputs,
// queued events and trace records.
//
// A Board is a value apart from that bus: its copy and assignment are the
// compiler's (= default: a member added later is copied with the rest); a
// copy talks to no bus until attach(), an assigned board keeps its own, and
// a copy goes on byte for byte as the original would. reset() is the
// controller's reset (a reload).
#pragma once
#include <array>
#include <cstdint>
#include <optional>

#include "board/pio.h"
#include "board/serial_port.h"
#include "board/settings.h"
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

// What a write to an I/O port leaves to the host.
enum class PortWrite : uint8_t {
  Done,    // the board's own (the PIO's control and data), or no device
  PortB,   // the PIO's port B: the plant's guns, solenoids, disc shooter
  Enb485,  // ENB485 changed (Devices::enb485)
};

// Everything on the board but the Z180: a plain value.
struct Devices {
  Devices(const StreamSeeds& seeds, const Settings& boardSettings)
      : memoryFill(seeds.memoryFill),
        eyeNoise(seeds.eyeNoise),
        gunLuck(seeds.gunLuck),
        muzzle(seeds.muzzle),
        dispersion(seeds.dispersion),
        settings(boardSettings) {}
  bool operator==(const Devices&) const = default;

  SerialPort serial;
  Pio pio;
  // Port A's edge lines (bit 1 fore, bit 0 aft): low while the plant's
  // detector or an injection holds them.
  uint8_t plantLow = 0, injectedLow = 0;
  uint8_t edgeLines = 0xFF;
  int enb485 = -1;  // never written
  plant::SplitMix64 memoryFill, eyeNoise, gunLuck, muzzle, dispersion;
  Settings settings;
  // Over the whole run: ad_rd8 calls per eye and the last value each
  // returned, interrupts accepted per source (vm::Irq).
  std::array<int64_t, 2> adReads{};
  std::array<int, 2> lastAdValue{-1, -1};
  // The decoy screen (index in the arena's deployed items) that hid the
  // opponent's beacon at the last eye read, or -1: screen_hides is traced
  // when it changes. Kept through a reset: it is the field's, not the
  // program's.
  int lastBeaconScreen = -1;
  std::array<uint64_t, vm::kIrqCount> interruptCounts{};
};

class Board : public Devices {
 public:
  // Powered on at tick 0, running `image` under the match's cost table
  // with this board's settings (costsFor), talking to `bus`.
  Board(const vm::Image& image, vm::Bus& bus, const vm::CostTable& matchCosts,
        const StreamSeeds& seeds, const Settings& settings);
  Board(const Board&) = default;
  Board& operator=(const Board&) = default;
  // A copy that talks to `bus`.
  Board(const Board& other, vm::Bus& bus) : Board(other) { attach(bus); }
  void attach(vm::Bus& bus) { cpu.attach(bus); }
  // The controller's reset at t: the Z180 as powered on at t (its RAM
  // filled from the next bytes of its stream, as a power cycle leaves new
  // garbage), the serial port and library idle, the PIO unarmed (it raises
  // nothing until the program arms it again), ENB485 unknown, no eye read
  // yet by the new program. The lines at the pins, the streams and the
  // counters go on. The port must be idle.
  void reset(Tick t);
  bool operator==(const Board& other) const {
    return cpu == other.cpu && Devices::operator==(other);
  }

  // The I/O ports as the board decodes them (vm/bytecode.h kPort*): a
  // write, and what it leaves to the host; a read (0xFF: no device).
  PortWrite out(uint16_t port, uint8_t value);
  uint8_t in(uint16_t port) const;

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
