-- A smoothing filter over 200 readings (a linear congruential generator,
-- 0 to 250) in functions with local variables: each reading with its two
-- neighbours weighted 1, 2, 1, then the position of the smoothed peak
-- found from the end; REPS times. Prints two smoothed values, the peaks'
-- positions summed (mod 10,000) and the repetitions. Same algorithm as
-- smooth.dc (bench/vs_lua.py).
local N, REPS = 200, 2000
local raw, smooth = {}, {}
local seed = 1

local function readings()
  for k = 0, N - 1 do
    seed = (seed * 13 + 29) % 2003
    raw[k] = seed // 8
  end
end

local function filter()
  smooth[0] = raw[0]
  smooth[N - 1] = raw[N - 1]
  for k = 1, N - 2 do
    smooth[k] = (raw[k - 1] + 2 * raw[k] + raw[k + 1]) // 4
  end
  local peak, at = smooth[0], 0
  local k = N - 1
  while k > 0 do
    if smooth[k] > peak then
      peak = smooth[k]
      at = k
    end
    k = k - 1
  end
  return at
end

local at = 0
local rep = 0
while rep < REPS do
  readings()
  at = (at + filter()) % 10000
  rep = rep + 1
end
print(string.format("%d %d %d %d", smooth[0], smooth[N // 2], at, rep))
