-- A scan of a 640-character text, REPS times: the letters 'e', the words
-- (a letter after a space or at the start) and the places where "robot"
-- begins, found by comparing character by character. Prints the three
-- counts and the repetitions. Same algorithm as strscan.dc.
local LEN, REPS = 640, 1200
local source = "the robot sees the other robot and fires "
local text, word = {}, {string.byte("robot", 1, 5)}
for i = 0, LEN - 1 do text[i] = source:byte(i % 41 + 1) end
local E, SPACE = string.byte("e"), string.byte(" ")
local es, words, found, rep = 0, 0, 0, 0
while rep < REPS do
  es, words, found = 0, 0, 0
  for i = 0, LEN - 1 do
    if text[i] == E then es = es + 1 end
    if text[i] ~= SPACE and (i == 0 or text[i - 1] == SPACE) then words = words + 1 end
    local match, k = true, 0
    while k < 5 and match do
      if i + k >= LEN or text[i + k] ~= word[k + 1] then match = false end
      k = k + 1
    end
    if match then found = found + 1 end
  end
  rep = rep + 1
end
print(string.format("%d %d %d %d", es, words, found, rep))
