-- Insertion sort of 150 readings (a linear congruential generator, 0 to
-- 998, less 500) in functions with local variables, REPS times; prints
-- the smallest, the largest, the element in the middle and the
-- repetitions. Same algorithm as insertion.dc (bench/vs_lua.py).
local N, REPS = 150, 300
local v = {}
local seed = 5

local function fill()
  for k = 0, N - 1 do
    seed = (seed * 13 + 11) % 999
    v[k] = seed - 500
  end
end

local function sort()
  for k = 1, N - 1 do
    local x = v[k]
    local j = k - 1
    while j >= 0 and v[j] > x do
      v[j + 1] = v[j]
      j = j - 1
    end
    v[j + 1] = x
  end
end

local rep = 0
while rep < REPS do
  fill()
  sort()
  rep = rep + 1
end
print(string.format("%d %d %d %d", v[0], v[N - 1], v[N // 2], rep))
