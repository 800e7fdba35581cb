-- The sum of the decimal digits of every number from 1 to N, and how many
-- of those sums are multiples of 7, REPS times; prints the last total of
-- the sums modulo 10,000, the count and the repetitions. Same algorithm as
-- digits.dc (bench/vs_lua.py).
local N, REPS = 2000, 200
local total, sevens = 0, 0
local rep = 0
while rep < REPS do
  total, sevens = 0, 0
  for i = 1, N do
    local n, s = i, 0
    while n > 0 do
      s = s + n % 10
      n = n // 10
    end
    total = (total + s) % 10000
    if s % 7 == 0 then sevens = sevens + 1 end
  end
  rep = rep + 1
end
print(string.format("%d %d %d", total, sevens, rep))
