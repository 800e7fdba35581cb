-- A table of 100 sightings (a table each: bearing, range, seen), drawn from
-- a linear congruential generator; REPS times, the nearest sighting seen,
-- how many were seen and the sum of their bearings modulo 1000. Prints the
-- three and the repetitions. Same algorithm as structs.dc.
local N, REPS = 100, 15000
local tbl = {}
local seed = 3
for i = 0, N - 1 do
  local s = {}
  seed = (seed * 29 + 7) % 1009
  s.bearing = seed % 360
  seed = (seed * 29 + 7) % 1009
  s.range = seed
  s.seen = seed % 3 ~= 0
  tbl[i] = s
end
local nearest, seen, bearings, rep = 0, 0, 0, 0
while rep < REPS do
  nearest, seen, bearings = 32767, 0, 0
  for i = 0, N - 1 do
    local s = tbl[i]
    if s.seen then
      seen = seen + 1
      bearings = (bearings + s.bearing) % 1000
      if s.range < nearest then nearest = s.range end
    end
  end
  rep = rep + 1
end
print(string.format("%d %d %d %d", nearest, seen, bearings, rep))
