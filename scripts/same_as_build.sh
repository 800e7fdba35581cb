#!/bin/bash
# same_as_build.sh OLD NEW [SHARED]: is NEW's 180-s ICEMAN vs fig92 match exactly OLD's?
# For seeds 1-5: the JSON (less wall_seconds) and the trace (--trace) of NEW
# byte for byte OLD's, and NEW's trace and JSON those of NEW
# --no-fast-forward but for the integrator's steps, right-hand sides and
# roots, which count work (the rule of tests/fast_forward_test.py). OLD and
# NEW are simbot binaries; SHARED defaults to ../shared.
# Prints IDENTICAL and exits 0, or names each difference and exits 1.
set -u
old=$1 new=$2 shared=${3:-../shared}
programs="$shared/programs/iceman.dc $shared/programs/fig92.dc"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
work_counts='"steps"\|"rhs_evals"\|"roots"'
status=0
for seed in 1 2 3 4 5; do
  for run in old new nff; do
    case $run in
      old) bin=$old extra= ;;
      new) bin=$new extra= ;;
      nff) bin=$new extra=--no-fast-forward ;;
    esac
    "$bin" match $programs --seconds 180 --seed $seed --json --trace "$work/$run.trace" $extra \
      2>/dev/null | grep -v '"wall_seconds"' > "$work/$run.json"
  done
  cmp -s "$work/old.json" "$work/new.json" || { echo "seed $seed: JSON differs from OLD's"; status=1; }
  cmp -s "$work/old.trace" "$work/new.trace" || { echo "seed $seed: trace differs from OLD's"; status=1; }
  cmp -s "$work/nff.trace" "$work/new.trace" ||
    { echo "seed $seed: trace differs from --no-fast-forward's"; status=1; }
  cmp -s <(grep -v "$work_counts" "$work/nff.json") <(grep -v "$work_counts" "$work/new.json") ||
    { echo "seed $seed: JSON differs from --no-fast-forward's"; status=1; }
done
[ $status = 0 ] && echo IDENTICAL
exit $status
