#!/usr/bin/env bash
# No source file over 1,000 lines (the house rules): a file that long has
# several jobs and is split by job. Counts every file of the checkout,
# tracked or new (git's ignore rules keep build folders and node_modules
# out), written in a language simbot is written in: C++ (.cpp, .h, .def),
# tests included, Python, JavaScript, shell and CMake. Documentation, robot
# programs (.dc: the thesis's are as they were written), profiles and data
# are not code and are not counted. Prints each file over the limit with
# its count and exits 1; scripts/test.sh's layout check and the
# layout.line_limit test both run it.
set -euo pipefail
cd "$(dirname "$0")/.."
limit=1000
over=0
while IFS= read -r -d '' file; do
  [ -f "$file" ] || continue
  lines=$(wc -l < "$file")
  if [ "$lines" -gt "$limit" ]; then
    echo "$file: $lines lines (at most $limit: split it by job)"
    over=1
  fi
done < <(git ls-files -z --cached --others --exclude-standard -- \
  '*.cpp' '*.h' '*.def' '*.py' '*.js' '*.mjs' '*.sh' '*.cmake' 'CMakeLists.txt' '*/CMakeLists.txt' \
  ':!:tests/browser/node_modules' .ci/run)
exit "$over"
