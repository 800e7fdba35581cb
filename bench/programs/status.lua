-- A robot's status word decoded: N words from a linear congruential
-- generator, each tested against its flag bits (bumpers front and back,
-- edge detectors fore and aft, the gun ready, a turn under way), with the
-- counts kept and a one-bit state flipped at each fore edge, REPS times;
-- prints the counts and the repetitions. Same algorithm as status.dc
-- (bench/vs_lua.py).
local N, REPS = 3000, 200
local BUMP_FRONT, BUMP_BACK, EDGE_FORE, EDGE_AFT = 0x01, 0x02, 0x04, 0x08
local GUN_READY, TURNING = 0x40, 0x300
local bumps, edges, shots, turns = 0, 0, 0, 0
local rep = 0
while rep < REPS do
  local seed = 7
  local state = 0
  bumps, edges, shots, turns = 0, 0, 0, 0
  for _ = 1, N do
    seed = (seed * 13 + 7) % 2039
    local w = seed
    if w & BUMP_FRONT ~= 0 then bumps = bumps + 1 end
    if w & BUMP_BACK ~= 0 then bumps = bumps + 1 end
    if w & EDGE_FORE ~= 0 then
      edges = edges + 1
      state = state ~ 1
    end
    if w & EDGE_AFT ~= 0 then edges = edges + 1 end
    if state & 1 ~= 0 and w & GUN_READY ~= 0 then shots = shots + 1 end
    if w & TURNING ~= 0 then turns = turns + 1 end
  end
  rep = rep + 1
end
print(string.format("%d %d %d %d %d", bumps, edges, shots, turns, rep))
