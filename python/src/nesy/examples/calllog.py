"""A JSON Lines log of the robot calls a server answers, shared by the examples."""

from __future__ import annotations

import json
import os
import sys
import threading
import time
from typing import Any, Dict, Optional, Union

__all__ = ["CallLog"]


class CallLog:
    """Writes one JSON object per line, each with ``t`` (seconds since the log was opened) and
    ``event``:

    - ``{"event": "session", "hello": {...}}`` when a session starts;
    - ``{"event": "call", "method": ..., "params": {...}, "result": ...}`` (or ``"error":
      {...}``) for each robot call answered, in order, with ``"check": true`` for the queries
      nesy makes for its own workspace checks rather than for the policy;
    - ``{"event": "stopped", "reason": ...}`` when the robot is stopped.

    ``path`` ``None`` logs nothing; ``"-"`` logs to standard error. The file is truncated when
    opened.
    """

    def __init__(self, path: Optional[Union[str, "os.PathLike[str]"]] = None):
        self.path = path
        self._lock = threading.Lock()
        self._opened = time.monotonic()
        if path is None:
            self._file = None
        elif os.fspath(path) == "-":
            self._file = sys.stderr
        else:
            self._file = open(path, "w", encoding="utf-8")

    def write(self, event: str, **fields: Any) -> None:
        """Writes one event line and flushes it."""
        if self._file is None:
            return
        record: Dict[str, Any] = {"t": round(time.monotonic() - self._opened, 3), "event": event}
        record.update(fields)
        line = json.dumps(record, default=repr)
        with self._lock:
            self._file.write(line + "\n")
            self._file.flush()

    def call(
        self,
        method: str,
        params: Dict[str, Any],
        result: Any = None,
        error: Optional[Dict[str, Any]] = None,
        check: bool = False,
    ) -> None:
        """Logs one answered call."""
        fields: Dict[str, Any] = {"method": method, "params": params}
        if check:
            fields["check"] = True
        if error is not None:
            fields["error"] = error
        else:
            fields["result"] = result
        self.write("call", **fields)

    def close(self) -> None:
        if self._file is not None and self._file is not sys.stderr:
            self._file.close()
        self._file = None
