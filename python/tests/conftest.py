"""Fixtures shared by the test files."""

import threading
import time

import pytest


@pytest.fixture
def ticks_during():
    """`run(call, period)`: calls `call()` while another Python thread ticks every
    `period` seconds, and gives its result and the ticks that fell inside the call
    (none while a call holds the GIL throughout)."""

    def run(call, period=0.001):
        ticks = []
        stop = threading.Event()

        def tick():
            while not stop.is_set():
                ticks.append(time.perf_counter())
                time.sleep(period)

        th = threading.Thread(target=tick)
        th.start()
        time.sleep(10 * period)
        start = time.perf_counter()
        try:
            result = call()
        finally:
            end = time.perf_counter()
            stop.set()
            th.join()
        return result, sum(start < x < end for x in ticks)

    return run
