#!/usr/bin/env bash
# The diffpills binary itself: exit status 0 / 1 / 2 / 3 and one output line per input line.
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
set +e
err=$("$bin" query extra-arg 2>&1 < /dev/null > /dev/null); status=$?
set -e
[ "$status" -eq 2 ] || { echo "query with an argument: exit $status, expected 2"; exit 1; }
grep -q "extra-arg" <<< "$err" || { echo "the misuse message does not name the argument: $err"; exit 1; }
help=$("$bin" --help)
grep -q "JSON" <<< "$help" && grep -q "exit status" <<< "$help" || { echo "--help does not explain query"; exit 1; }
grep -q "^  3 " <<< "$help" || { echo "--help does not document exit status 3"; exit 1; }

# A failed write ends the command with status 3 and a message, not silently with 0 (or 141).
set +e
err=$(printf '%s\n' "$query" | "$bin" query 2>&1 > /dev/full); status=$?
set -e
[ "$status" -eq 3 ] || { echo "query > /dev/full: exit $status, expected 3"; exit 1; }
grep -q "cannot write to standard output" <<< "$err" || { echo "query > /dev/full: no message: $err"; exit 1; }
set +e
err=$("$bin" --help 2>&1 > /dev/full); status=$?
set -e
[ "$status" -eq 3 ] && grep -q "cannot write" <<< "$err" || { echo "--help > /dev/full: exit $status"; exit 1; }

# A reader that goes away: `head -n 1` exits after the first answer. The ~1.5 MB of answers to
# 10^6 bytes of queries cannot fit in a pipe's buffer (64 KiB), so writing fails with EPIPE
# whatever the scheduling, and the command must say so and exit 3, not die of SIGPIPE (141).
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
set +e
yes "$query" | head -c 1000000 | "$bin" query 2> "$work/errors" | head -n 1 > "$work/first"
statuses=("${PIPESTATUS[@]}")
set -e
[ "${statuses[2]}" -eq 3 ] || { echo "closed pipe: exit ${statuses[2]}, expected 3"; exit 1; }
grep -q "cannot write to standard output" "$work/errors" || { echo "closed pipe: no message"; exit 1; }
grep -q '"phi":0.90999999' "$work/first" || { echo "closed pipe: first answer wrong"; exit 1; }

# A read error (a directory as standard input: read(2) fails with EISDIR) is reported too.
set +e
err=$("$bin" query 2>&1 < / > /dev/null); status=$?
set -e
[ "$status" -eq 3 ] || { echo "query < /: exit $status, expected 3"; exit 1; }
grep -q "cannot read standard input" <<< "$err" || { echo "query < /: no message: $err"; exit 1; }
demo=$("$bin" demo)
grep -q "phi" <<< "$demo" || { echo "demo prints no phi"; exit 1; }
echo "cli exit status: ok"
