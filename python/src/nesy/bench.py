"""Benchmark runs from Python: ``nesy bench run`` and the unit records it writes.

A run folder (``nesy bench run RUN_DIR``) holds ``manifest.json``, ``results/`` with one JSON
Lines file per shard (``shard-0-of-1.jsonl``: one record per finished unit, appended as each
unit ends), ``units/`` (each unit's artifacts) and, once every unit is done, the report. Running
the same command on the folder again resumes it.
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Union

__all__ = ["BenchRecords", "run", "records"]

PathLike = Union[str, "os.PathLike[str]"]


class BenchRecords(list):
    """The unit records of a run folder (a ``list`` of dicts), with how the command ended.

    Attributes:
        exit_code: 0 when every unit of the run (or shard) is done, 1 when some are not (the
            run stopped early, e.g. on a cost or error-rate limit; run it again to resume).
        complete: ``exit_code == 0``.
        output: what the command printed on standard output (the report's path, if written).
        log: what it printed on standard error (progress and the closing summary).
    """

    exit_code: int = 0
    output: str = ""
    log: str = ""

    @property
    def complete(self) -> bool:
        return self.exit_code == 0


def records(run_dir: PathLike) -> List[Dict[str, Any]]:
    """Reads every unit record of a run folder: each line of each ``results/*.jsonl`` (in file
    name order, then line order), as the binary wrote it.

    A record is a dict with: ``scenario`` (e.g. ``"obst_low_02_s0"``), ``variant`` and
    ``method`` (e.g. ``"nesycr"``, ``"demo2code"``), ``repeat``, ``factor`` and ``complexity``
    (the table cell), ``obstruction_change``, ``seed``, ``config_hash``, ``status``
    (``"succeeded"``, ``"method_error"``, ...), ``error`` (text or ``None``), ``scores``
    (``sr``, ``gc``, ``latched_sr``, ``latched_gc``, ``pd``, ``label``, ``achieved``,
    ``subtasks``), ``effort`` (model ``calls``, ``images``, ``calls_by_purpose``, ``tokens``,
    ``cost_usd`` and seconds per stage), ``artifacts`` (the unit's folder under the run folder)
    and ``finished_at`` (UTC time).

    A line that is not JSON (a unit being written as the file is read) is skipped with a
    warning.
    """
    folder = Path(run_dir) / "results"
    found: List[Dict[str, Any]] = []
    if not folder.is_dir():
        return found
    for path in sorted(folder.glob("*.jsonl")):
        with open(path, encoding="utf-8") as handle:
            for number, line in enumerate(handle, start=1):
                if not line.strip():
                    continue
                try:
                    record = json.loads(line)
                except ValueError:
                    warnings.warn("{}:{}: not a JSON record; skipped".format(path, number))
                    continue
                if isinstance(record, dict):
                    found.append(record)
    return found


def run(
    run_dir: PathLike,
    *,
    methods: Optional[Union[str, Sequence[str]]] = None,
    observation: Optional[str] = None,
    sample: Optional[int] = None,
    vlm: Optional[str] = None,
    extra_args: Sequence[Any] = (),
) -> BenchRecords:
    """Runs (or resumes) a benchmark into ``run_dir`` with ``nesy bench run`` and returns the
    unit records read back from the folder (see ``records``; the list also carries
    ``exit_code``, ``complete``, ``output`` and ``log``).

    Args:
        run_dir: the run folder (created if new; resumed if it exists).
        methods: methods and variants: a comma-separated string or a list
            (``["nesycr", "imitation"]``, ``"nesycr+verification=off"``); default ``nesycr``.
        observation: ``"images"`` or ``"state-text"``.
        sample: keep a random sample of this many scenarios.
        vlm: ``"oracle"``, ``"replay:DIR"`` or the URL of an OpenAI-compatible server.
        extra_args: more ``nesy bench run`` arguments (``["--scenarios", "comb_medium",
            "--jobs", "2"]``).

    Raises:
        nesy.NesyError: exit code 2 (bad input, or the run could not be set up).
    """
    from . import _fail, _invoke

    args: List[Any] = ["bench", "run", run_dir]
    if methods is not None:
        args += ["--methods", methods if isinstance(methods, str) else ",".join(methods)]
    if observation is not None:
        args += ["--observation", observation]
    if sample is not None:
        args += ["--sample", int(sample)]
    if vlm is not None:
        args += ["--vlm", vlm]
    args += list(extra_args)
    done = _invoke(args)
    if done.returncode not in (0, 1):
        raise _fail("nesy bench run", done)
    found = BenchRecords(records(run_dir))
    found.exit_code = done.returncode
    found.output = done.stdout
    found.log = done.stderr
    return found
