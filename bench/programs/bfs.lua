-- Breadth-first search over a 16 x 16 grid whose walls (a quarter of the
-- cells) come from a linear congruential generator, from the corner, with
-- a queue in an array and a function that visits a neighbour; a new grid
-- each of REPS times; prints the last search's farthest distance and cells
-- reached, and the farthest distances' total. Same algorithm as bfs.dc
-- (bench/vs_lua.py).
local W, N, REPS = 16, 256, 1000
local wall, dist, queue = {}, {}, {}
local tail, reached = 0, 0

local function visit(n, d)
  if wall[n] == 0 and dist[n] < 0 then
    dist[n] = d
    queue[tail] = n
    tail = tail + 1
    reached = reached + 1
  end
end

local seed, total, far = 1, 0, 0
for _ = 1, REPS do
  for i = 0, N - 1 do
    seed = (seed * 25 + 13) % 1021
    wall[i] = (seed % 4 == 0) and 1 or 0
    dist[i] = -1
  end
  wall[0] = 0
  dist[0] = 0
  local head = 0
  tail = 0
  queue[tail] = 0
  tail = tail + 1
  far = 0
  reached = 1
  while head < tail do
    local cell = queue[head]
    head = head + 1
    if dist[cell] > far then far = dist[cell] end
    if cell % W > 0 then visit(cell - 1, dist[cell] + 1) end
    if cell % W < W - 1 then visit(cell + 1, dist[cell] + 1) end
    if cell >= W then visit(cell - W, dist[cell] + 1) end
    if cell < N - W then visit(cell + W, dist[cell] + 1) end
  end
  total = total + far
end
print(string.format("%d %d %d", far, reached, total))
