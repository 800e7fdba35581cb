-- 256 eye readings (0 to 1008) from a linear congruential generator; REPS
-- times, a moving average over 8 readings and the times it rises through
-- 500 (above 500 after being at or below it). Prints the crossings, the
-- last average and the repetitions. Same algorithm as filter.dc.
local N, WINDOW, REPS = 256, 8, 5000
local readings = {}
local seed = 5
for i = 0, N - 1 do
  seed = (seed * 29 + 7) % 1009
  readings[i] = seed
end
local crossings, average, rep = 0, 0, 0
while rep < REPS do
  local sum, previous = 0, 0
  crossings = 0
  for i = 0, N - 1 do
    sum = sum + readings[i]
    if i >= WINDOW then sum = sum - readings[i - WINDOW] end
    if i >= WINDOW - 1 then
      average = sum // WINDOW
      if average > 500 and previous <= 500 then crossings = crossings + 1 end
      previous = average
    end
  end
  rep = rep + 1
end
print(string.format("%d %d %d", crossings, average, rep))
