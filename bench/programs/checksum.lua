-- A table-driven checksum of a 256-byte message: each byte's table entry
-- (64 integers, picked by a computed index) mixed into a running sum
-- modulo 10,007, REPS times with one byte changed each time; prints the
-- sum, two table entries and the repetitions. Same algorithm as
-- checksum.dc (bench/vs_lua.py).
local LEN, REPS = 256, 6000
local tbl, msg = {}, {}
local seed = 9
for i = 0, 63 do
  seed = (seed * 21 + 17) % 1009
  tbl[i] = seed
end
for i = 0, LEN - 1 do msg[i] = (i * 7 + 3) & 255 end
local sum = 0
local rep = 0
while rep < REPS do
  msg[rep % LEN] = rep & 255
  for i = 0, LEN - 1 do
    sum = (sum * 3 + tbl[(sum + msg[i]) & 63]) % 10007
  end
  rep = rep + 1
end
print(string.format("%d %d %d %d", sum, tbl[0], tbl[63], rep))
