"""Long computations release the GIL: while one runs in a thread, the main thread keeps running
Python code. With the GIL held the main thread would not run at all until the call returns."""

import threading
import time

import numpy as np
import pytest

import tiltnoise

NOISE = np.random.default_rng(0).standard_normal(2**24)


def main_thread_progress(work):
    """Iterations of a Python loop in the main thread while `work` runs in another thread."""
    done = threading.Event()
    errors = []

    def run():
        try:
            work()
        except BaseException as e:  # noqa: BLE001 - reported below
            errors.append(e)
        finally:
            done.set()

    t = threading.Thread(target=run)
    count = 0
    start = time.perf_counter()
    t.start()
    while not done.is_set():
        count += 1
        time.sleep(0)  # lets the worker take the GIL where it needs it
    t.join()
    assert not errors, errors
    return count, time.perf_counter() - start


@pytest.mark.parametrize(
    "name, work",
    [
        ("transfer", lambda m: m.transfer(np.logspace(-4, 1, 200_000), method="direct",
                                          threads=1)),
        ("welch", lambda m: tiltnoise.welch(NOISE, nperseg=2**16)),
        ("monte_carlo", lambda m: m.monte_carlo(samples=20_000, threads=1)),
    ],
)
def test_computations_let_python_run(name, work):
    model = tiltnoise.Model()
    count, seconds = main_thread_progress(lambda: work(model))
    # The worker runs for a good part of a second; the main thread loops thousands of times
    # meanwhile (each iteration takes a microsecond or so). Held, the GIL would allow a few.
    assert seconds > 0.05, f"{name}: too short to tell ({seconds:.3f} s)"
    assert count > 100, f"{name}: the main thread ran {count} iterations in {seconds:.2f} s"
