-- A ring buffer of 16 readings written and read through functions with
-- local variables: REPS rounds of 10 puts and 7 gets, each get adding to a
-- running total; prints the total (mod 10,000), the readings left, the
-- puts dropped (mod 65,536) and the repetitions. Same algorithm as ring.dc
-- (bench/vs_lua.py).
local SIZE, REPS = 16, 30000
local ring = {}
local head, tail, count, total, dropped = 0, 0, 0, 0, 0

local function put(v)
  if count == SIZE then
    dropped = dropped + 1
    return
  end
  ring[tail] = v
  tail = (tail + 1) % SIZE
  count = count + 1
end

local function get()
  if count == 0 then return 0 end
  local v = ring[head]
  head = (head + 1) % SIZE
  count = count - 1
  return v
end

local rep = 0
while rep < REPS do
  for k = 0, 9 do put((rep + k * 7) % 101) end
  for k = 0, 6 do total = (total + get()) % 10000 end
  rep = rep + 1
end
-- dropped is a 16-bit int in ring.dc: it wraps
print(string.format("%d %d %d %d", total, count, dropped & 0xFFFF, rep))
