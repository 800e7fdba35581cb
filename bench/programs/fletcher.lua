-- Fletcher-16 checksums of a 300-byte message (bytes from a linear
-- congruential generator), the message changed at one place between
-- repetitions, REPS times. Same algorithm as fletcher.dc (bench/vs_lua.py).
local LEN, REPS = 300, 8000
local msg = {}
local seed, odd, sum1, sum2 = 3, 0, 0, 0
for i = 0, LEN - 1 do
  seed = (seed * 13 + 7) % 251
  msg[i] = seed
end
local rep = 0
while rep < REPS do
  msg[rep % LEN] = rep & 255
  sum1, sum2 = 0, 0
  for i = 0, LEN - 1 do
    sum1 = (sum1 + msg[i]) % 255
    sum2 = (sum2 + sum1) % 255
  end
  if (sum1 ~ sum2) & 1 == 1 then odd = odd + 1 end
  rep = rep + 1
end
print(string.format("%d %d %d %d", sum1, sum2, odd, rep))
