-- How many months from 1900 to 2099 have a Friday the 13th, by Zeller's
-- congruence, REPS times; prints the count, the sum of the weekdays
-- modulo 1,000 and the repetitions. Same algorithm as weekday.dc
-- (bench/vs_lua.py).
local FIRST, LAST, REPS = 1900, 2099, 300
local fridays, weekdays = 0, 0
local rep = 0
while rep < REPS do
  fridays, weekdays = 0, 0
  for year = FIRST, LAST do
    for month = 1, 12 do
      -- January and February count as months 13 and 14 of the year before
      local m, y = month, year
      if m < 3 then
        m = m + 12
        y = y - 1
      end
      local k = y % 100
      local j = y // 100
      -- h: 0 is Saturday, 6 is Friday
      local h = (13 + 13 * (m + 1) // 5 + k + k // 4 + j // 4 + 5 * j) % 7
      if h == 6 then fridays = fridays + 1 end
      weekdays = (weekdays + h) % 1000
    end
  end
  rep = rep + 1
end
print(string.format("%d %d %d", fridays, weekdays, rep))
