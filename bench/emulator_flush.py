"""What a pty's output flush discards, with no emulator at all: one JSON line.

Run as ``python bench/emulator_flush.py --gap-us 50 --reader process`` (standard library only).
A client writes a 10-byte packet to a pty's slave, waits ``--gap-us`` (busy, as a client
building its next packet), then flushes the slave's output (``tcflush(TCOFLUSH)``, what pyserial's
``reset_output_buffer`` and so pypot do before every packet); a packet counts as lost when fewer
than its 10 bytes ever reach the master's side. ``--reader none``: nobody reads the master until
the packet's verdict (1 ms later); ``--reader process``: a process of its own blocks in
``read()`` on the master the whole time and hands each byte on through a pipe at once (the
fastest reader Python can have). Equal losses mean the flush discards the bytes before any
reader could have had them: in the kernel, not in a slow reader.

Then, with no flush and nobody reading, it times the kernel's worker itself: for each of
``--count`` writes, how long until the master's input queue (``FIONREAD``) holds the whole
packet (``moved_us``: p50, p99, and how many took longer than ``--gap-us``). A write whose bytes
take longer than the client's gap to get there is one its flush would discard.
"""

from __future__ import annotations

import argparse
import fcntl
import json
import os
import select
import signal
import struct
import sys
import termios
import time
import tty

PACKET = bytes(range(10))
VERDICT_S = 0.001
MOVE_TIMEOUT_S = 0.05
PAUSE_S = 0.0002  # between timed writes, as a client between packets


def _moved_us(master: int, slave: int, count: int) -> list[float]:
    """Per write, the µs until the master's input queue holds all of it (nobody reads)."""
    queued = bytearray(4)
    delays = []
    clock = time.perf_counter
    for _ in range(count):
        start = clock()
        os.write(slave, PACKET)
        while True:
            fcntl.ioctl(master, termios.FIONREAD, queued)
            now = clock()
            if struct.unpack("i", queued)[0] >= len(PACKET) or now - start > MOVE_TIMEOUT_S:
                break
        delays.append((now - start) * 1e6)
        os.read(master, 4096)
        until = clock() + PAUSE_S
        while clock() < until:
            pass
    return sorted(delays)


def _quantile(ordered: list[float], q: float) -> float:
    return round(ordered[min(len(ordered) - 1, int(q * len(ordered)))], 1) if ordered else 0.0


def _reader(master: int, pipe_w: int) -> None:
    """The child: forward everything read on the master into the pipe, until killed."""
    while True:
        data = os.read(master, 4096)
        if not data:
            os._exit(0)
        os.write(pipe_w, data)


def main() -> int:
    """Write, wait, flush ``--count`` times; print how many packets never arrived whole."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--gap-us", type=float, default=50.0)
    parser.add_argument("--count", type=int, default=1000)
    parser.add_argument("--reader", choices=("none", "process"), default="none")
    args = parser.parse_args()
    master, slave = os.openpty()
    tty.setraw(master)
    tty.setraw(slave)
    child = 0
    source = master
    if args.reader == "process":
        pipe_r, pipe_w = os.pipe()
        child = os.fork()  # before any thread exists: a plain fork is safe here
        if child == 0:
            os.close(pipe_r)
            _reader(master, pipe_w)
        os.close(pipe_w)
        source = pipe_r
    os.set_blocking(source, False)
    time.sleep(0.1)  # the reader is blocked in read() by now
    lost = 0
    gap_s = args.gap_us / 1e6
    try:
        for _ in range(args.count):
            os.write(slave, PACKET)
            until = time.perf_counter() + gap_s
            while time.perf_counter() < until:
                pass
            termios.tcflush(slave, termios.TCOFLUSH)
            got = 0
            deadline = time.perf_counter() + VERDICT_S
            while got < len(PACKET) and (left := deadline - time.perf_counter()) > 0:
                ready, _, _ = select.select([source], [], [], left)
                if ready:
                    got += len(os.read(source, 4096))
            lost += got < len(PACKET)
    finally:
        if child:
            os.kill(child, signal.SIGKILL)
            os.waitpid(child, 0)
    delays = _moved_us(master, slave, args.count) if args.reader == "none" else []
    record = {"reader": args.reader, "gap_us": args.gap_us, "count": args.count, "lost": lost}
    if delays:
        record["moved_us"] = {
            "p50": _quantile(delays, 0.5),
            "p99": _quantile(delays, 0.99),
            "over_gap": sum(1 for delay in delays if delay > args.gap_us),
        }
    sys.stdout.write(json.dumps(record) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
