"""bench/server_cpu and server_baseline: CPU per request is the CPU a server spent over a run
divided by what it served, its background taken out, and each round compares like with like
(the figures themselves are the bench's, not the tests')."""

from __future__ import annotations

import os
import threading

from bench.server_baseline import baseline_cpu_table, calls_table
from bench.server_cpu import cpu_per_request, net_of_background, thread_cpu_ns
from tests.helpers.waiting import eventually


def test_cpu_per_request_counts_every_thread_and_names_the_busiest() -> None:
    before = {"1": 1_000_000, "2": 5_000_000}
    after = {"1": 3_000_000, "2": 6_000_000, "3": 1_000_000}  # thread 3 started during the run
    spent = cpu_per_request(before, after, requests=100)
    assert spent == {"cpu_us": 40.0, "serving_cpu_us": 20.0}
    assert cpu_per_request(before, after, requests=0) == {}
    assert net_of_background(spent, background_ns=1_000_000, requests=100) == {"net_cpu_us": 30.0}


def test_this_process_threads_are_read_from_proc() -> None:
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            sum(range(1000))

    before = sum(thread_cpu_ns(os.getpid()).values())
    worker = threading.Thread(target=spin)
    worker.start()
    try:
        assert eventually(lambda: len(thread_cpu_ns(os.getpid())) >= 2)
        assert eventually(lambda: sum(thread_cpu_ns(os.getpid()).values()) > before)
    finally:
        stop.set()
        worker.join()


def _runs(cpu: list[float]) -> dict[str, object]:
    runs = [
        {"rep": rep, "load1": 10.0, "cpu_us": c, "net_cpu_us": c - 10, "serving_cpu_us": c - 20}
        for rep, c in enumerate(cpu)
    ]
    return {"register GET": {"runs": runs}}


def test_the_cpu_table_pairs_runs_of_the_same_round() -> None:
    table, notes = baseline_cpu_table(_runs([100.0, 200.0]), _runs([50.0, 300.0]), "abc")
    first = ["register GET", "2", "150.0", "175.0", "1.000 (0.50 – 1.50), 1 of 2"]
    assert table.rows[0][:5] == first
    assert "less background" in table.headers[5]
    assert notes


def test_the_calls_table_says_the_difference() -> None:
    now = {"register GET": {"calls": 128.0, "cpu_us": 70.0}}
    base = {"register GET": {"calls": 137.0, "cpu_us": 90.0}}
    table, _ = calls_table({"poppy": now, "baseline": base}, "abc")
    assert table.rows == [["register GET", "137", "128", "-9", "90.0", "70.0"]]
    alone, _ = calls_table({"poppy": now}, None)
    assert alone.rows == [["register GET", "128", "70.0"]]
