"""Progress of long work: a tqdm bar when tqdm is installed, else a plain line on stderr per
tenth of the work; either only once the work has taken :data:`DELAY_S` (quick work stays quiet)."""

from __future__ import annotations

import sys
import time
from typing import Any, Callable, Optional, Union

ProgressArg = Union[bool, Callable[[int, int], None], None]

#: Seconds of work before any progress is shown.
DELAY_S = 2.0


class _Bar:
    """``callback(done, total)`` for the compiled module; :meth:`close` ends the bar."""

    def __init__(self, description: str, unit: str) -> None:
        self._description = description
        self._unit = unit
        self._bar: Any = None
        self._last_line = -1.0
        self._start = time.monotonic()

    def __call__(self, done: int, total: int) -> None:
        if self._bar is None:
            try:
                from tqdm.auto import tqdm  # optional dependency: scatterfit[progress]
            except ImportError:
                self._bar = False
            else:
                self._bar = tqdm(
                    total=total, desc=self._description, unit=self._unit, leave=False, delay=DELAY_S
                )
        if self._bar is False:
            # Without tqdm: one line per tenth of the work.
            fraction = done / total if total else 1.0
            if time.monotonic() - self._start < DELAY_S:
                return
            if fraction - self._last_line >= 0.1 or done == total:
                self._last_line = fraction
                print(f"{self._description}: {done}/{total} {self._unit}", file=sys.stderr)
            return
        # update() (not refresh()) keeps tqdm's delay: quick work shows no bar.
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar:
            self._bar.close()


def progress_callback(
    progress: ProgressArg, description: str, unit: str
) -> tuple[Optional[Callable[[int, int], None]], Callable[[], None]]:
    """The callback to hand to the compiled module, and how to close it.

    ``progress`` is ``True`` (a bar), ``False``/``None`` (nothing) or your own
    ``callable(done, total)``.
    """
    if progress is True:
        bar = _Bar(description, unit)
        return bar, bar.close
    if callable(progress):
        return progress, lambda: None
    return None, lambda: None
