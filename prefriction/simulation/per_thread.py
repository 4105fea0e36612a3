"""Objects built once per process and key, with the parts that calls write to kept per thread.

A compiled CasADi Function is built (or loaded) once per structure and process and shared by
all threads; the numpy argument and result buffers it is called through, and CasADi's call
memory behind them, belong to one thread. Two threads running the same structure therefore
never write into each other's buffers, and a serial run pays one dictionary lookup.
"""

from __future__ import annotations

import threading
from typing import Any, Callable, Hashable

__all__ = ["PerThread"]


class PerThread:
    """A cache of ``key -> shared`` (built once, under a lock) and ``key -> local(shared)`` per thread."""

    def __init__(self) -> None:
        self._shared: dict = {}
        self._lock = threading.Lock()
        self._local = threading.local()

    def __len__(self) -> int:
        """Shared objects built so far (one per key)."""
        return len(self._shared)

    def get(self, key: Hashable, build: Callable[[], Any], local: Callable[[Any], Any]) -> tuple[Any, Any, bool]:
        """This thread's part for ``key``, the shared part, and whether this call built the shared part.

        ``build()`` makes the shared part (once per process, other threads wait for it);
        ``local(shared)`` the thread's own part (once per thread).
        """
        mine = getattr(self._local, "objects", None)
        if mine is None:
            mine = self._local.objects = {}
        if key in mine:
            return (*mine[key], False)
        with self._lock:
            built = key not in self._shared
            if built:
                self._shared[key] = build()
            shared = self._shared[key]
        mine[key] = (local(shared), shared)
        return (*mine[key], built)
