-- Recursive Fibonacci: fib(N) computed REPS times; prints fib(N) and the
-- repetitions. Same algorithm as fib.dc (bench/vs_lua.py compares them).
local N, REPS = 23, 30
local function fib(n)
  if n < 2 then return n end
  return fib(n - 1) + fib(n - 2)
end
local r, k = 0, 0
while k < REPS do
  r = fib(N)
  k = k + 1
end
print(string.format("%d %d", r, k))
