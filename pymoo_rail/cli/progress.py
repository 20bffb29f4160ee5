"""Progress on every wait: a bar per generation, and a ticking clock for a computation without steps."""

from __future__ import annotations

import sys
import threading
import time
from contextlib import contextmanager
from typing import Iterator

WAIT_DELAY_S = 2.0
"""A wait shorter than this shows nothing."""


class GenerationBar:
    """pymoo callback that advances a tqdm bar by one per generation."""

    def __init__(self, bar):
        self.bar = bar

    def __call__(self, algorithm) -> None:
        self.bar.update(1)


@contextmanager
def ticking(description: str, disable: bool = False, delay_s: float = WAIT_DELAY_S) -> Iterator[None]:
    """Show ``description: 00:12`` on standard error, ticking each second, while the block runs.

    Nothing is shown if the block ends within ``delay_s``; after a longer wait the line stays,
    with the time it took. A thread ticks the clock: a Numba kernel that holds the interpreter for
    a while only delays a tick.
    """
    from tqdm import tqdm

    bar = tqdm(total=None, desc=description, bar_format="{desc}: {elapsed}", delay=delay_s, disable=disable,
               file=sys.stderr)
    stop = threading.Event()
    started = time.monotonic()

    def tick() -> None:
        while not stop.wait(1.0):
            if time.monotonic() - started >= delay_s:
                bar.update(0)  # redraws the clock (and marks the line as shown, so close ends it)

    thread = threading.Thread(target=tick, name="pymoo-rail-ticking", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        if time.monotonic() - started >= delay_s:
            bar.update(0)
        bar.close()
