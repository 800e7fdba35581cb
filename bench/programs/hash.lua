-- An open-addressing hash table of 128 integer keys: 90 keys from a linear
-- congruential generator inserted (hash (key * 31) & 127, linear probing,
-- duplicates kept out), then 200 keys looked up, REPS times with a new
-- seed each time; prints the last round's probes and hits and the total
-- of probes modulo 10,000. Same algorithm as hash.dc (bench/vs_lua.py).
local SIZE, KEYS, LOOKS, REPS = 128, 90, 200, 2000
local keys, used = {}, {}
local total, probes, hits = 0, 0, 0
for rep = 0, REPS - 1 do
  local seed = rep % 433 + 1
  for i = 0, SIZE - 1 do used[i] = 0 end
  probes, hits = 0, 0
  for _ = 1, KEYS do
    seed = (seed * 75 + 74) % 433
    local key = seed * 2 + rep % 2
    local h = (key * 31) & (SIZE - 1)
    while used[h] ~= 0 and keys[h] ~= key do
      h = (h + 1) & (SIZE - 1)
      probes = probes + 1
    end
    used[h] = 1
    keys[h] = key
  end
  for k = 0, LOOKS - 1 do
    local key = (k * 7) % 1000
    local h = (key * 31) & (SIZE - 1)
    while used[h] ~= 0 and keys[h] ~= key do
      h = (h + 1) & (SIZE - 1)
      probes = probes + 1
    end
    if used[h] ~= 0 then hits = hits + 1 end
  end
  total = (total + probes) % 10000
end
print(string.format("%d %d %d", probes, hits, total))
