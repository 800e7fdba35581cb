// board/pio.cpp -- the PIO's port A (pio.h).
#include "board/pio.h"

namespace simbot::board {

void Pio::control(uint8_t word) {
  switch (expect_) {
    case Expect::Direction:
      direction_ = word;
      expect_ = Expect::Any;
      lastCondition_ = condition();
      return;
    case Expect::Mask:
      mask_ = word;
      expect_ = Expect::Any;
      // A new mask re-arms the comparison: only a later change to true counts.
      lastCondition_ = condition();
      return;
    case Expect::Any:
      break;
  }
  if ((word & 0x01) == 0) {  // interrupt vector
    vector_ = word;
    return;
  }
  switch (word & 0x0F) {
    case 0x0F:  // mode word
      mode_ = word >> 6;
      if (mode_ == 3) expect_ = Expect::Direction;
      return;
    case 0x07:  // interrupt control word
      enabled_ = (word & 0x80) != 0;
      andMode_ = (word & 0x40) != 0;
      activeHigh_ = (word & 0x20) != 0;
      if (word & 0x10) expect_ = Expect::Mask;
      lastCondition_ = condition();
      return;
    case 0x03:  // interrupt enable/disable word
      enabled_ = (word & 0x80) != 0;
      return;
    default:
      return;  // not a word the PIO decodes; ignored as the chip does
  }
}

bool Pio::condition() const {
  if (mode_ != 3) return false;
  const uint8_t monitored = static_cast<uint8_t>(~mask_ & direction_);
  if (monitored == 0) return false;
  const uint8_t active = activeHigh_ ? lines_ : static_cast<uint8_t>(~lines_);
  const uint8_t hits = active & monitored;
  return andMode_ ? hits == monitored : hits != 0;
}

bool Pio::setInputs(uint8_t lines) {
  lines_ = lines;
  const bool now = condition();
  const bool rising = now && !lastCondition_;
  lastCondition_ = now;
  if (!rising || !enabled_) return false;
  if (inService_) {
    heldRequest_ = true;
    return false;
  }
  return true;
}

bool Pio::returned() {
  inService_ = false;
  if (!heldRequest_) return false;
  heldRequest_ = false;
  return enabled_;
}

uint8_t Pio::read() const {
  return static_cast<uint8_t>((lines_ & direction_) | (output_ & ~direction_));
}

}  // namespace simbot::board
