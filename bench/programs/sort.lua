-- Insertion sort of 200 integers drawn from a linear congruential
-- generator, REPS times; prints the smallest, the middle and the largest
-- value and the repetitions. Same algorithm as sort.dc (bench/vs_lua.py).
local N, REPS = 200, 200
local a = {}
local seed, rep = 1, 0
while rep < REPS do
  for i = 0, N - 1 do
    seed = (seed * 29 + 7) % 1009
    a[i] = seed
  end
  for i = 1, N - 1 do
    local key = a[i]
    local j = i - 1
    while j >= 0 and a[j] > key do
      a[j + 1] = a[j]
      j = j - 1
    end
    a[j + 1] = key
  end
  rep = rep + 1
end
print(string.format("%d %d %d %d", a[0], a[N // 2], a[N - 1], rep))
