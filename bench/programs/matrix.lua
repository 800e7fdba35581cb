-- A 12 x 12 integer matrix product in a function with local variables,
-- REPS times; prints two elements, the trace (mod 10,000) and the
-- repetitions. Same algorithm as matrix.dc (bench/vs_lua.py).
local M, REPS = 12, 600
local p, q, c = {}, {}, {}
for r = 0, M - 1 do p[r], q[r], c[r] = {}, {}, {} end

local function multiply()
  for r = 0, M - 1 do
    for j = 0, M - 1 do
      local s = 0
      for k = 0, M - 1 do s = s + p[r][k] * q[k][j] end
      c[r][j] = s
    end
  end
end

for r = 0, M - 1 do
  for j = 0, M - 1 do
    p[r][j] = (r + 2 * j) % 7 - 3
    q[r][j] = (3 * r + j) % 5 - 2
  end
end
local rep = 0
while rep < REPS do
  multiply()
  rep = rep + 1
end
local trace = 0
for r = 0, M - 1 do trace = math.fmod(trace + c[r][r], 10000) end
print(string.format("%d %d %d %d", c[0][0], c[M - 1][M - 2], math.tointeger(trace), rep))
