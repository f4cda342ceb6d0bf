"""Reading a run directory (what ``rubblepile run``, ``resume``, ``impact`` … write) into Python objects."""

from __future__ import annotations

import csv
import json
import os
from typing import Any, Dict, List, Optional, Union

import numpy as np

PathLike = Union[str, "os.PathLike[str]"]


def _read_csv(path: str) -> Dict[str, np.ndarray]:
    """A CSV file with a header as a dict column name -> array (booleans for true/false columns, floats where every
    cell parses, else strings)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    out: Dict[str, np.ndarray] = {}
    for k, name in enumerate(header):
        cells = [r[k] if k < len(r) else "" for r in body]
        if cells and all(c in ("true", "false") for c in cells):
            out[name] = np.array([c == "true" for c in cells], dtype=bool)
            continue
        try:
            out[name] = np.array([float(c) for c in cells], dtype=float)
        except ValueError:
            out[name] = np.array(cells, dtype=object)
    return out


def read_run(dir: PathLike) -> Dict[str, Any]:
    """Reads the run directory ``dir``.

    Returns a dict with ``summary`` (``summary.json`` as a dict, ``None`` while the run has not ended),
    ``timeseries`` (``timeseries.csv``: column name -> array, e.g. ``t`` in s, ``wall_seconds`` in s),
    ``snapshots`` (a list of ``(k, path)`` of ``snapshots/<k>.csv`` in order), ``scene`` (the text of the run's
    ``scene.toml`` copy) and ``checkpoint`` (whether ``checkpoint.json`` is there). Read a snapshot with
    :func:`read_snapshot`.
    """
    dir = os.fspath(dir)
    if not os.path.isdir(dir):
        raise FileNotFoundError(f"{dir}: not a run directory")
    summary: Optional[Dict[str, Any]] = None
    sp = os.path.join(dir, "summary.json")
    if os.path.isfile(sp):
        with open(sp) as f:
            summary = json.load(f)
    ts = os.path.join(dir, "timeseries.csv")
    timeseries = _read_csv(ts) if os.path.isfile(ts) else {}
    snaps: List[tuple] = []
    sd = os.path.join(dir, "snapshots")
    if os.path.isdir(sd):
        for name in os.listdir(sd):
            stem, ext = os.path.splitext(name)
            if ext == ".csv" and stem.isdigit():
                snaps.append((int(stem), os.path.join(sd, name)))
    snaps.sort()
    scene = None
    sc = os.path.join(dir, "scene.toml")
    if os.path.isfile(sc):
        with open(sc) as f:
            scene = f.read()
    return {
        "dir": dir,
        "summary": summary,
        "timeseries": timeseries,
        "snapshots": snaps,
        "scene": scene,
        "checkpoint": os.path.isfile(os.path.join(dir, "checkpoint.json")),
    }


def read_snapshot(path: PathLike) -> Dict[str, np.ndarray]:
    """Reads one snapshot file (``snapshots/<k>.csv``, ``last_good_state.csv``): column name -> array (SI units as
    the file's header names them: positions ``x, y, z`` in m, velocities ``vx, vy, vz`` in m/s, …)."""
    return _read_csv(os.fspath(path))
