#!/bin/sh
# Run a command (default: `make test`) with busy loops beside it, as on a loaded CI machine.
#
#   sh tests/loaded.sh                          # the whole suite, 2 busy loops
#   LOOPS=4 sh tests/loaded.sh make test-fast   # 4 busy loops
#   sh tests/loaded.sh .venv/bin/pytest -q -p no:xdist tests/motion/test_move_play.py
#
# Each busy loop keeps one core busy; the loops are stopped when the command ends (or is
# interrupted), and the command's exit status is this script's. See docs/testing.md.
set -u
LOOPS=${LOOPS:-2}
[ "$#" -gt 0 ] || set -- make test
pids=""
stop() {
    [ -n "$pids" ] && kill $pids 2>/dev/null
    pids=""
}
trap stop EXIT
trap 'stop; exit 130' INT TERM
i=0
while [ "$i" -lt "$LOOPS" ]; do
    (while :; do :; done) &
    pids="$pids $!"
    i=$((i + 1))
done
echo "loaded.sh: $LOOPS busy loop(s) ($pids ), load $(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo ?); running: $*" >&2
"$@"
status=$?
stop
exit "$status"
