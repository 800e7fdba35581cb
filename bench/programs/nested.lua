-- A nested-loop sum in 16-bit int arithmetic that wraps, as nested.dc:
-- s = s + i*j + 7 over I x J iterations, kept to 16 bits with & 0xFFFF
-- (addition and multiplication modulo 2^16 agree with the Z180's), then
-- printed as a signed 16-bit int.
local I, J = 2000, 2000
local s = 0
for i = 0, I - 1 do
  for j = 0, J - 1 do
    s = (s + i * j + 7) & 0xFFFF
  end
end
if s >= 0x8000 then s = s - 0x10000 end
print(string.format("%d", s))
