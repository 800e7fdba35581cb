// scheduler/robot_bus.cpp -- a robot's bus: what its VM's accesses do.
//
// The VM calls these at the exact tick of each access (vm::Bus): port B
// writes and PIO handler entries become plant inputs applied after the
// round, A/D reads the plant's eye readings at their tick, the serial
// library's calls drive the board's serial port, whose bytes the plant's
// motor controller receives (a latched frame sets the wheels), PIO port A
// follows the edge lines, and
// each leaves its trace record. The round loop that runs the VMs and
// applies the inputs is in match.cpp.
#include <bit>
#include <string>
#include <utility>
#include <vector>

#include "scheduler/match_impl.h"

namespace simbot::scheduler::detail {

// The board decodes its ports; port B and ENB485 are the host's to carry on.
void Robot::out(Tick t, uint16_t port, uint8_t value) {
  switch (board.out(port, value)) {
    case board::PortWrite::PortB:
      match->inputs().push_back(
          {t, index, PlantInput::Kind::PortB, value, plant::Bumper::Front, tracedWatch(t)});
      if (match->tracing()) match->emit(t, trace::rec::PortB{index, value});
      return;
    case board::PortWrite::Enb485:
      if (match->tracing()) match->emit(t, trace::rec::Rs485{index, value});
      return;
    case board::PortWrite::Done:
      return;
  }
}

uint8_t Robot::in(Tick, uint16_t port) { return board.in(port); }

int Robot::adSample(Tick t, int channel) {
  // Only the eye asked for is computed; the noise stream advances as for both.
  const plant::EyeChannels asked = channel == 0   ? plant::EyeChannels::Left
                                   : channel == 1 ? plant::EyeChannels::Right
                                                  : plant::EyeChannels::Both;
  const plant::EyeReadings e = [&] {
    const PartScope plant(match->clock(), PartClock::Plant);
    return match->arena().eyeReadings(index, t, &board.eyeNoise, asked);
  }();
  const int value = channel == 0 ? e.left : channel == 1 ? e.right : 0;
  if (match->observer()) match->observer()->onEyeRead(index, t, channel, value);
  if (channel == 0 || channel == 1) {
    // Traced as a step when it differs: a search loop reads thousands a second.
    const auto c = static_cast<size_t>(channel);
    ++board.adReads[c];
    if (match->tracing() && value != board.lastAdValue[c])
      match->emit(t, trace::rec::AdRead{index, channel, value, board.adReads[c]});
    board.lastAdValue[c] = value;
    if (e.beaconScreen != board.lastBeaconScreen) {
      if (match->tracing()) {
        if (board.lastBeaconScreen >= 0) emitScreenHides(t, board.lastBeaconScreen, false);
        if (e.beaconScreen >= 0) emitScreenHides(t, e.beaconScreen, true);
      }
      board.lastBeaconScreen = e.beaconScreen;
    }
  }
  return value;
}

// Screen `item` of the arena's deployed items began (hidden) or ceased to
// hide the opponent's beacon from this robot's eyes; the screen is named
// as its deploy record names it (its robot, its number in its table).
void Robot::emitScreenHides(Tick t, int item, bool hidden) {
  const std::vector<plant::Deployed>& items = match->arena().deployed();
  const plant::Deployed& screen = items[static_cast<size_t>(item)];
  int number = 0;
  for (int k = 0; k <= item; ++k) {
    const plant::Deployed& d = items[static_cast<size_t>(k)];
    if (d.robot == screen.robot && d.table == screen.table) ++number;
  }
  match->emit(t, trace::rec::ScreenHides{index, screen.robot, number, hidden});
}

// The call chain of the send under way: the VM's frames and then the
// library call itself (pc() has moved past it by now). The start-up code's
// call of main, in no function, is left out.
Robot::SendSite Robot::sendSite(Tick t) const {
  const vm::Image& image = spec.image;
  std::vector<vm::Vm::Frame> frames = board.cpu.frames();
  std::erase_if(frames, [&](const vm::Vm::Frame& f) {
    return f.at + 1 == mainReturn || !image.functionAt(f.at) || image.lineAt(f.at) <= 0;
  });
  const vm::Vm::Frame send{board.cpu.libraryCallPc(), false};
  auto name = [&](uint32_t at) {
    const vm::Symbol* fn = image.functionAt(at);
    return fn ? fn->name : std::string();
  };
  SendSite site{t, image.lineAt(send.at), name(send.at), 0, "", ""};
  // A handler's own code has no caller: it was not called.
  if (!frames.empty() && !frames.back().interrupted) {
    site.callerLine = image.lineAt(frames.back().at);
    site.callerFunction = name(frames.back().at);
  }
  frames.push_back(send);
  site.calls = chainText(frames);
  return site;
}

std::string Robot::chainText(const std::vector<vm::Vm::Frame>& frames) const {
  const vm::Image& image = spec.image;
  auto entry = [&](const vm::Vm::Frame& f) {
    const vm::Symbol* fn = image.functionAt(f.at);
    return (fn ? fn->name : std::string()) + ':' + std::to_string(image.lineAt(f.at));
  };
  std::string out;
  for (size_t i = 0; i < frames.size();) {
    const std::string here = entry(frames[i]);
    size_t j = i + 1;
    while (j < frames.size() && frames[j - 1].interrupted == frames[i].interrupted &&
           entry(frames[j]) == here)
      ++j;
    if (i) out += frames[i - 1].interrupted ? " > interrupt > " : " > ";
    out += here;
    if (j - i > 1) out += " x " + std::to_string(j - i);
    i = j;
  }
  return out;
}

std::pair<std::string, int> Robot::faultChain() const {
  const vm::Image& image = spec.image;
  std::vector<vm::Vm::Frame> frames = board.cpu.frames();
  std::erase_if(frames, [&](const vm::Vm::Frame& f) { return f.at + 1 == mainReturn; });
  const int depth = static_cast<int>(frames.size());
  frames.push_back({board.cpu.fault() ? board.cpu.fault()->pc : board.cpu.pc(), false});
  std::erase_if(frames, [&](const vm::Vm::Frame& f) {
    return !image.functionAt(f.at) || image.lineAt(f.at) <= 0;
  });
  return {chainText(frames), depth};
}

// The records of a send, kept out of serialSend so that an untraced run's
// path stays as short as it was.
void Robot::traceSend(Tick t, int count) {
  SendSite site = sendSite(t);
  match->emit(t, trace::rec::SerialSend{index, count, site.line, site.function, site.callerLine,
                                        site.callerFunction, site.calls});
  sendBefore = std::exchange(lastSend, std::move(site));
}

void Robot::traceOverwrite(Tick t, const board::OverwrittenSend& overwritten) {
  // The overwritten send is the latest before this one; a snapshot or
  // reload that lost it leaves its lines 0.
  const SendSite before = sendBefore.t == overwritten.sentAt ? sendBefore : SendSite{};
  match->emit(t, trace::rec::FrameOverwritten{
                     index, overwritten.sentAt, overwritten.count, overwritten.fetched,
                     lastSend.line, lastSend.function, lastSend.callerLine, lastSend.callerFunction,
                     before.line, before.function, before.callerLine, before.callerFunction});
}

void Robot::serialSend(Tick t, uint16_t buf, uint16_t cc) {
  // The call's effect (the library takes buf[0], *cc counts it) happens at
  // T0, so the records made at T0 carry the values from before it
  // (docs/trace.md, "watch"); the next boundary shows it.
  if (match->tracing() && !watches.empty() && !(tickStart && tickStart->first == t))
    tickStart.emplace(t, watchedValues());
  if (match->tracing()) traceSend(t, board.cpu.read8(cc));  // *cc as the program set it
  if (const auto overwritten = board.serialSend(t, buf, cc)) {
    ++result.framesOverwritten;
    if (match->tracing()) traceOverwrite(t, *overwritten);
  }
  scheduleSerial(t);
}

void Robot::serialTxService(Tick t, vm::Vm&) {
  board.serialService(t);
  scheduleSerial(t);
}

// A byte that entered the shift register is on the wire for one character
// time, ending at nextByteDone().
void Robot::scheduleSerial(Tick) {
  const auto done = board.serial.nextByteDone();
  if (done && *done != serialEventAt) {
    serialEventAt = *done;
    if (match->tracing())
      match->emit(*done - timebase::kTicksPerChar,
                  trace::rec::SerialByte{index, board.serial.shifting()});
    match->queue().schedule(*done, EventClass::SerialByte,
                            {QueuedEvent::Kind::SerialByte, index, 0});
  }
}

// The byte's stop bit ended at t: the motor controller has received it.
void Robot::byteDone(Tick t) {
  serialEventAt = -1;
  const std::optional<uint8_t> byte = board.serialByteDone(t);
  if (const auto frame = byte ? receiver.receive(*byte) : std::nullopt) {
    if (match->observer()) match->observer()->onFrame(index, t, frame->command.has_value());
    if (frame->command) {
      ++result.framesLatched;
      const PartScope plant(match->clock(), PartClock::Plant);
      match->arena().setWheels(index, *frame->command, t);
      motorCommand = *frame->command;
      if (battery) match->powerChanged(index, t);
      debugEvent(t, DebugEvent::FrameLatched);
    } else {
      ++result.framesRejected;
    }
    if (match->tracing()) {
      if (frame->command)
        match->emit(t, trace::rec::FrameLatched{index, frame->bytes});
      else
        match->emit(t, trace::rec::FrameRejected{index, frame->bytes});
    }
  }
  scheduleSerial(t);
}

// A --watch expression's value now, from the innermost frame: a number
// for a scalar, the debugger's text for an aggregate, null when it names
// an auto that is not in scope here.
trace::WatchValue Robot::expressionValue(const inspect::Expression& e) const {
  try {
    const inspect::Scope scope(board.cpu);
    const inspect::Value v = e.evaluate(scope);
    int64_t integer = 0;
    double real = 0;
    bool isFloat = false;
    if (inspect::scalar(scope, v, integer, real, isFloat))
      return isFloat ? trace::WatchValue{real} : trace::WatchValue{integer};
    return inspect::format(scope, v);
  } catch (const inspect::Error&) {
    return nullptr;
  }
}

// Each watched variable's value as its C type reads it (the compiler's
// vm::Symbol::Value; resolveWatches admits scalars only).
trace::Watch Robot::tracedWatch(Tick t) const {
  if (!match->tracing() || watches.empty()) return {};
  return tickStart && tickStart->first == t ? tickStart->second : watchedValues();
}

trace::Watch Robot::watchedValues() const {
  using V = vm::Symbol::Value;
  trace::Watch values;
  for (const auto& w : watches) {
    if (w.expression) {
      values.emplace_back(w.name, expressionValue(*w.expression));
      continue;
    }
    trace::WatchValue v;
    switch (w.value) {
      case V::Char:
        v = std::int64_t{board.cpu.read8(w.address)};
        break;
      case V::SChar:
        v = std::int64_t{static_cast<int8_t>(board.cpu.read8(w.address))};
        break;
      case V::Int:
        v = std::int64_t{static_cast<int16_t>(board.cpu.read16(w.address))};
        break;
      case V::UInt:
      case V::Pointer:
        v = std::int64_t{board.cpu.read16(w.address)};
        break;
      case V::Long:
        v = std::int64_t{static_cast<int32_t>(board.cpu.read32(w.address))};
        break;
      case V::ULong:
        v = std::int64_t{board.cpu.read32(w.address)};
        break;
      case V::Float:
        v = static_cast<double>(std::bit_cast<float>(board.cpu.read32(w.address)));
        break;
      case V::Aggregate:
      case V::Code:
        continue;
    }
    values.emplace_back(w.name, v);
  }
  return values;
}

void Robot::updateEdgeLines(Tick t) {
  if (board.updateEdgeLines() && match->tracing())
    match->emit(t, trace::rec::PortA{index, board.edgeLines});
}

void Robot::inject(Tick t, const Injection& injection) {
  match->fired(injection);
  if (match->tracing())
    match->emit(t, trace::rec::Injection{index, injection.text, board.cpu.line()});
  switch (injection.source) {
    case InjectSource::EdgeFore:
    case InjectSource::EdgeAft: {
      const uint8_t bit = injection.source == InjectSource::EdgeFore ? 0x02 : 0x01;
      board.injectedLow |= bit;
      updateEdgeLines(t);
      match->queue().schedule(t + kInjectedEdgePulse, EventClass::Injection,
                              {QueuedEvent::Kind::ReleaseEdge, index, bit});
      return;
    }
    case InjectSource::Reset:
      // Only at a time (config/inject.cpp refuses a program point): between rounds.
      match->resetBoard(index, t, true);
      return;
    case InjectSource::BumperFront:
    case InjectSource::BumperBack: {
      const plant::Bumper side = injection.source == InjectSource::BumperFront
                                     ? plant::Bumper::Front
                                     : plant::Bumper::Back;
      // Between rounds (a time or tick) the plant takes it at once; at a
      // program point it waits for the end of the round with port B writes.
      if (match->betweenRounds())
        match->applyReflex(t, index, side);
      else
        match->inputs().push_back({t, index, PlantInput::Kind::Reflex, 0, side, tracedWatch(t)});
      return;
    }
  }
}

void Robot::console(Tick t, std::string_view line) {
  result.console.emplace_back(line);
  if (match->tracing()) match->emit(t, trace::rec::Console{index, std::string(line)});
}

// The #INT_VEC handler the PIO's vector selects.
std::string Robot::handlerName() const {
  for (const auto& v : spec.image.vectors)
    if (v.vector == board.pio.vector()) return v.handlerName;
  return "";
}

void Robot::interruptAccepted(Tick t, vm::Irq irq, uint32_t pc) {
  ++board.interruptCounts[static_cast<size_t>(irq)];
  if (match->observer()) match->observer()->onInterruptAccepted(index, t, irq);
  if (irq == vm::Irq::Pio) {
    board.pio.accepted();
    debugEvent(t, DebugEvent::EdgeAccepted);
    match->inputs().push_back(
        {t, index, PlantInput::Kind::EdgeHandler, 0, plant::Bumper::Front, tracedWatch(t)});
  }
  // The BIOS timer service (1,024 a second) is counted, not traced.
  if (!match->tracing() || irq == vm::Irq::Timer) return;
  if (irq == vm::Irq::SerialTx) {
    // Traced as one span when it returns, with the values it found.
    serialIsrAccepted = t;
    serialIsrWatch = tracedWatch(t);
    return;
  }
  const vm::Symbol* fn = spec.image.functionAt(pc);
  match->emit(t, trace::rec::InterruptAccepted{index, std::string(vm::irqName(irq)),
                                               spec.image.lineAt(pc), fn ? fn->name : "",
                                               irq == vm::Irq::Pio ? handlerName() : ""});
}

void Robot::interruptReturned(Tick t, vm::Irq irq) {
  if (irq == vm::Irq::SerialTx) {
    if (match->tracing())
      match->emit(serialIsrAccepted, trace::rec::SerialIsr{index, t}, std::move(serialIsrWatch));
    return;
  }
  if (irq != vm::Irq::Pio) return;
  if (match->tracing())
    match->emit(t, trace::rec::InterruptReturned{index, std::string(vm::irqName(irq))});
  board.pioReturned();
}

void Robot::iffChanged(Tick t, bool iff1) {
  if (match->tracing()) match->emit(t, trace::rec::Iff1{index, iff1});
}

bool Robot::wantCostateEvents() const { return match->tracingCostates(); }

// Only a change of state is recorded (trace/records.def, docs/trace.md).
// A costatement rests between passes either waiting at the line it gave way
// at, or at its top (ended, or never run). The VM reports every entry,
// give-way and end; of these the record keeps
//   - the first entry ever (enter);
//   - a give-way at a line the costatement was not already waiting at
//     (yield): a waitfor re-checked and still false writes nothing, as does
//     the entry that resumed it;
//   - an end that follows a wait or the first entry (end): a costatement
//     that runs from its top to its end without giving way, pass after pass,
//     writes nothing after its first pass.
// An entry after an end or a wait is not recorded when it happens (whether
// the wait is over is known only at the next give-way or end).
// The costatement is named by its CoData's symbol: the name a named one
// was given, "costate@LINE" for an unnamed one (FUNCTION.costate@LINE).
void Robot::costate(Tick t, uint16_t coData, CostateEvent e, int line) {
  const auto [it, first] = costates.try_emplace(coData);
  CoState& co = it->second;
  bool record = false;
  switch (e) {
    case CostateEvent::Enter:
      record = first;
      if (first)
        co.rest = CoRest::Started;
      else if (co.rest == CoRest::Waiting)
        co.rest = CoRest::Resumed;
      else if (co.rest == CoRest::Ended)
        co.rest = CoRest::FromTop;
      break;
    case CostateEvent::Yield:
      record = !(co.rest == CoRest::Resumed && co.line == line);
      co = {CoRest::Waiting, line};
      break;
    case CostateEvent::End:
      record = co.rest != CoRest::FromTop;
      co = {CoRest::Ended, 0};
      break;
  }
  if (!record) return;
  std::string name = fmt::format("0x{:04x}", coData);
  for (const auto& s : spec.image.symbols)
    if (s.address == coData && s.size == vm::kCoDataSize &&
        (s.kind == vm::Symbol::Kind::Global || s.kind == vm::Symbol::Kind::Static)) {
      name = s.name.substr(s.name.find('.') + 1);
      break;
    }
  static constexpr const char* kEvent[] = {"enter", "yield", "end"};
  match->emit(t, trace::rec::Costate{index, name, kEvent[static_cast<int>(e)], line});
}

}  // namespace simbot::scheduler::detail
