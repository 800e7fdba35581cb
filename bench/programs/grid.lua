-- A 32 x 32 grid of integers, REPS times: filled with (row * column) mod
-- 17, then the interior cells whose four neighbours sum to more than 32
-- are counted. Prints the count and the repetitions. Same algorithm as
-- grid.dc.
local SIDE, REPS = 32, 600
local g = {}
for r = 0, SIDE - 1 do g[r] = {} end
local count, rep = 0, 0
while rep < REPS do
  for r = 0, SIDE - 1 do
    local row = g[r]
    for c = 0, SIDE - 1 do row[c] = (r * c) % 17 end
  end
  count = 0
  for r = 1, SIDE - 2 do
    for c = 1, SIDE - 2 do
      if g[r - 1][c] + g[r + 1][c] + g[r][c - 1] + g[r][c + 1] > 32 then count = count + 1 end
    end
  end
  rep = rep + 1
end
print(string.format("%d %d", count, rep))
