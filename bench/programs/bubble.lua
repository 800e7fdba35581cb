-- Bubble sort of 120 integers from a linear congruential generator, with
-- a swap through a temporary and an early exit when a pass swaps nothing,
-- REPS times. Same algorithm as bubble.dc (bench/vs_lua.py).
local N, REPS = 120, 400
local v = {}
local seed, rep, swaps = 11, 0, 0
while rep < REPS do
  for i = 0, N - 1 do
    seed = (seed * 17 + 5) % 1013
    v[i] = seed - 500
  end
  swaps = 0
  local pass = N - 1
  local swapped = true
  while swapped do
    swapped = false
    for i = 0, pass - 1 do
      if v[i] > v[i + 1] then
        local tmp = v[i]
        v[i] = v[i + 1]
        v[i + 1] = tmp
        swapped = true
        swaps = swaps + 1
      end
    end
    pass = pass - 1
  end
  rep = rep + 1
end
print(string.format("%d %d %d %d", v[0], v[N - 1], swaps, rep))
