// Pieces of Dynamic C that several test fixtures' programs share, written
// once. Each is whole lines, so a fixture that splices one in keeps the
// line numbers its test names.
#pragma once

namespace simbot::testkit {

// ICEMAN's set-up of the PIO's port A (iceman.dc, lines 25-30; board/pio.h
// has the control words): mode 3, every line an input, the interrupt
// vector PIOA_VEC, interrupts enabled on any monitored line going low with
// a mask of 0xfc (lines 0 and 1, the fore and aft edge sensors, monitored),
// then the same control word without a mask. Six lines, for main()'s body;
// the program names its edge handler with "#INT_VEC PIOA_VEC".
inline constexpr const char* kArmPortA =
    "    outport(PIOCA, 0xff);\n"
    "    outport(PIOCA, 0xff);\n"
    "    outport(PIOCA, PIOA_VEC);\n"
    "    outport(PIOCA, 0x97);\n"
    "    outport(PIOCA, 0xfc);\n"
    "    outport(PIOCA, 0x87);\n";

}  // namespace simbot::testkit
