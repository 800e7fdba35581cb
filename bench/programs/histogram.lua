-- A histogram of 1,000 readings (0 to 1,020, a linear congruential
-- generator) into 16 bins of 64, REPS times, then the fullest bin and its
-- count. Same algorithm as histogram.dc (bench/vs_lua.py).
local N, BINS, REPS = 1000, 16, 2000
local bins = {}
local seed, rep, best, most = 7, 0, 0, 0
while rep < REPS do
  for b = 0, BINS - 1 do bins[b] = 0 end
  for i = 0, N - 1 do
    seed = (seed * 23 + 74) % 1021
    local x = seed
    bins[x // 64] = bins[x // 64] + 1
  end
  best = 0
  most = bins[0]
  for b = 1, BINS - 1 do
    if bins[b] > most then
      most = bins[b]
      best = b
    end
  end
  rep = rep + 1
end
print(string.format("%d %d %d", best, most, rep))
