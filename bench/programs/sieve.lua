-- Sieve of Eratosthenes over an 8,000-entry array, run REPS times; prints
-- the number of primes below 8,000 and the repetitions. Same algorithm as
-- sieve.dc (bench/vs_lua.py compares them).
local SIZE, REPS = 8000, 100
local flags = {}
local count, rep = 0, 0
while rep < REPS do
  count = 0
  for i = 0, SIZE - 1 do flags[i] = 1 end
  for i = 2, SIZE - 1 do
    if flags[i] ~= 0 then
      count = count + 1
      for j = i + i, SIZE - 1, i do flags[j] = 0 end
    end
  end
  rep = rep + 1
end
print(string.format("%d %d", count, rep))
