#!/usr/bin/env bash
# The diffpills binary itself: exit status 0 / 1 / 2 and one output line per input line.
set -euo pipefail
bin="$1"
query='{"a": {"type": "capsule", "length": 2, "radius": 0.2, "r": [0,0,0], "q": [1,0,0,0]}, "b": {"type": "capsule", "length": 1, "radius": 0.1, "r": [0,0,1], "q": [1,0,0,0]}}'

out=$(printf '%s\n%s\n' "$query" "$query" | "$bin" query); status=$?
[ "$status" -eq 0 ] || { echo "valid lines: exit $status, expected 0"; exit 1; }
[ "$(printf '%s\n' "$out" | wc -l)" -eq 2 ] || { echo "expected 2 answers"; exit 1; }
printf '%s\n' "$out" | grep -q '"phi":0.90999999' || { echo "unexpected answer: $out"; exit 1; }

set +e
out=$(printf '%s\nbroken\n%s\n' "$query" "$query" | "$bin" query); status=$?
set -e
[ "$status" -eq 1 ] || { echo "a bad line: exit $status, expected 1"; exit 1; }
[ "$(printf '%s\n' "$out" | wc -l)" -eq 3 ] || { echo "expected 3 answers"; exit 1; }
[ "$(printf '%s\n' "$out" | sed -n 2p | cut -c1-9)" = '{"error":' ] || { echo "line 2 should be an error"; exit 1; }

set +e
"$bin" frobnicate > /dev/null 2>&1; status=$?
set -e
[ "$status" -eq 2 ] || { echo "misuse: exit $status, expected 2"; exit 1; }
help=$("$bin" --help)
grep -q "JSON" <<< "$help" && grep -q "exit status" <<< "$help" || { echo "--help does not explain query"; exit 1; }
demo=$("$bin" demo)
grep -q "phi" <<< "$demo" || { echo "demo prints no phi"; exit 1; }
echo "cli exit status: ok"
