-- CRC-16 (CCITT polynomial 0x1021, bit by bit) of a 64-byte message from a
-- linear congruential generator, the message changed at one place between
-- repetitions, REPS times; prints the last CRC, the count of odd CRCs and
-- the repetitions. Same algorithm as crc16.dc (bench/vs_lua.py).
local LEN, REPS = 64, 5000
local msg = {}
local seed = 5
for i = 0, LEN - 1 do
  seed = (seed * 17 + 11) % 251
  msg[i] = seed
end
local odd, crc, rep = 0, 0, 0
while rep < REPS do
  msg[rep % LEN] = rep & 255
  crc = 0xFFFF
  for i = 0, LEN - 1 do
    crc = crc ~ (msg[i] << 8)
    for _ = 0, 7 do
      if crc & 0x8000 ~= 0 then
        crc = ((crc << 1) ~ 0x1021) & 0xFFFF
      else
        crc = (crc << 1) & 0xFFFF
      end
    end
  end
  if crc & 1 ~= 0 then odd = odd + 1 end
  rep = rep + 1
end
print(string.format("%d %d %d", crc, odd, rep))
