#!/bin/sh
# Run commands at the same time; exit with the first failing one's status (0 if all passed).
#
#   sh tests/together.sh 'MAIN COMMAND' 'OTHER COMMAND' ...
#
# Each OTHER COMMAND is one simple command (run with `exec`, so that a stop reaches it).
# The first command runs in the foreground with its output as it comes; each other one runs
# beside it with its output kept, printed whole once it ends (in the order given), under a line
# naming it and its exit status, so outputs never interleave. `make test` runs mypy and the
# OpenGL tests beside the parallel suite this way: the suite mostly waits, and they fill the
# cores it leaves idle (docs/testing.md). Last, a recap: each command's exit status with the
# failed tests and the summary line of its pytest output. Ctrl-C or a TERM stops them all.
set -u
[ "$#" -gt 0 ] || { echo "usage: sh tests/together.sh 'MAIN COMMAND' 'OTHER COMMAND' ..." >&2; exit 2; }
main=$1
shift
logs=$(mktemp -d "${TMPDIR:-/tmp}/together.XXXXXX") || exit 1
stop() {
    for pidfile in "$logs"/*.pid; do
        [ -f "$pidfile" ] && kill "$(cat "$pidfile" 2>/dev/null)" 2>/dev/null
    done
}
trap 'stop; rm -rf "$logs"' EXIT
trap 'stop; exit 130' INT TERM
i=0
for command in "$@"; do
    i=$((i + 1))
    printf '%s\n' "$command" >"$logs/$i.command"
    (
        sh -c "exec $command" >"$logs/$i.out" 2>&1 &
        echo $! >"$logs/$i.pid"
        wait $!
        echo $? >"$logs/$i.status"
        rm -f "$logs/$i.pid"
    ) &
    echo "together.sh: started beside: $command" >&2
done
echo "$main"
# how many run beside it (tests/conftest.py's worker count); its output is kept too, for the recap
{
    TOGETHER_BESIDE=$i sh -c "$main"
    echo $? >"$logs/0.status"
} 2>&1 | tee "$logs/0.out"
status=$(cat "$logs/0.status" 2>/dev/null || echo 1)
wait
j=0
while [ "$j" -lt "$i" ]; do
    j=$((j + 1))
    code=$(cat "$logs/$j.status" 2>/dev/null || echo 1)
    echo
    echo "==== $(cat "$logs/$j.command") (exit $code) ===="
    cat "$logs/$j.out"
    [ "$status" -eq 0 ] && [ "$code" -ne 0 ] && status=$code
done
# The recap last, so that a log showing only its tail (a CI summary) names what failed.
echo
echo "==== recap ===="
printf '%s\n' "$main" >"$logs/0.command"
j=0
while [ "$j" -le "$i" ]; do
    code=$(cat "$logs/$j.status" 2>/dev/null || echo 1)
    echo "$(cat "$logs/$j.command") (exit $code)"
    grep -E '^(FAILED|ERROR) |^=+ .*(passed|failed|error).* in [0-9.]+s' "$logs/$j.out" | sed 's/^/    /'
    j=$((j + 1))
done
exit "$status"
