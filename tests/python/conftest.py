"""Shared helpers of the Python front's tests (run by `.ci/python`)."""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "targets" / "examples"
# Columns (CSV) and keys (JSON) that measure the machine, not the physics (as tests/golden.rs).
MACHINE = ("wall_seconds", "events_per_second")


def cli_binary() -> pathlib.Path:
    """The command line to compare with: $RUBBLEPILE_BIN, else target/release/rubblepile of this checkout."""
    path = pathlib.Path(os.environ.get("RUBBLEPILE_BIN", ROOT / "target" / "release" / "rubblepile"))
    if not path.is_file():
        pytest.skip(f"{path} is not built: `cargo build --release` first")
    return path


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(cli_binary()), *args], capture_output=True, text=True, cwd=ROOT)


def scrub(path: pathlib.Path) -> str:
    """A run file's text with what measures the machine removed."""
    text = path.read_text()
    if path.suffix == ".json":
        return "".join(
            line + "\n"
            for line in text.splitlines()
            if not any(line.lstrip().startswith(f'"{k}"') for k in MACHINE)
        )
    if path.suffix == ".csv":
        lines = text.splitlines()
        if not lines:
            return text
        header = lines[0].split(",")
        drop = {k for k, c in enumerate(header) if c in MACHINE}
        return "".join(
            ",".join(c for k, c in enumerate(line.split(",")) if k not in drop) + "\n" for line in lines
        )
    return text


def run_files(dir: pathlib.Path) -> dict:
    """Every file of a run directory (relative path -> scrubbed text), the lock and the manifest (whose checksums
    cover the wall-clock columns) left out."""
    out = {}
    for p in sorted(dir.rglob("*")):
        if p.is_file() and not p.name.startswith(".") and p.name != "manifest.txt":
            out[str(p.relative_to(dir))] = scrub(p)
    return out


def raw_files(dir: pathlib.Path) -> dict:
    """Every file of a run directory as bytes (the lock left out)."""
    return {
        str(p.relative_to(dir)): p.read_bytes()
        for p in sorted(dir.rglob("*"))
        if p.is_file() and not p.name.startswith(".")
    }


def summary(dir: pathlib.Path) -> dict:
    return json.loads((dir / "summary.json").read_text())
