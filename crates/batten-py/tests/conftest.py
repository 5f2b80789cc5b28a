"""Shared fixtures: test curves, and the `batten` CLI binary for the parity tests."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[3]


def noisy_sine(n: int = 120, seed: int = 0, amplitude: float = 0.01) -> np.ndarray:
    """A sine over two half-waves with Gaussian noise in y."""
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 2.0 * np.pi, n)
    return np.column_stack([x, np.sin(x) + amplitude * rng.standard_normal(n)])


def noisy_circle(n: int = 80, seed: int = 0, amplitude: float = 0.01) -> np.ndarray:
    """A closed noisy circle of radius 1 (the first point not repeated)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    r = 1.0 + amplitude * rng.standard_normal(n)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def same_bits(a: Any, b: Any, path: str = "") -> None:
    """Assert `a` and `b` are equal, floats bit for bit (so -0.0 != 0.0 and NaN == NaN)."""
    if isinstance(a, float) or isinstance(b, float):
        assert isinstance(a, float) and isinstance(b, float), f"{path}: {a!r} vs {b!r}"
        assert struct.pack("<d", a) == struct.pack("<d", b), f"{path}: {a!r} vs {b!r}"
    elif isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), f"{path}: keys {list(a)} vs {list(b)}"
        for k in a:
            same_bits(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: {a!r} vs {b!r}"
        for i, (x, y) in enumerate(zip(a, b)):
            same_bits(x, y, f"{path}[{i}]")
    else:
        assert type(a) is type(b) and a == b, f"{path}: {a!r} vs {b!r}"


def same_array_bits(a: np.ndarray, b: np.ndarray) -> None:
    assert a.shape == b.shape and a.dtype == b.dtype == np.float64
    assert a.tobytes() == b.tobytes()


def write_csv(path: Path, points: np.ndarray) -> Path:
    """Points as CSV with every float in its shortest exact form (`repr`), as the CLI reads;
    `x,y` or, for an (n, 3) array, `x,y,z`."""
    header = "x,y,z" if points.shape[1] == 3 else "x,y"
    lines = [header] + [",".join(repr(float(v)) for v in row) for row in points]
    path.write_text("\n".join(lines) + "\n")
    return path


def noisy_helix(n: int = 150, seed: int = 0, amplitude: float = 0.01) -> np.ndarray:
    """Two turns of a helix of radius 1 and pitch 0.5 per turn, Gaussian noise per coordinate."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 4.0 * np.pi, n)
    truth = np.column_stack([np.cos(t), np.sin(t), 0.5 * t / (2.0 * np.pi)])
    return truth + amplitude * rng.standard_normal((n, 3))


def read_csv(path: Path) -> np.ndarray:
    rows = path.read_text().splitlines()[1:]
    return np.array([[float(v) for v in r.split(",")] for r in rows], dtype=np.float64)


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `batten` binary: $BATTEN_CLI, else target/release or target/debug of the repo."""
    candidates = [os.environ.get("BATTEN_CLI")] + [
        str(REPO / "target" / p / "batten") for p in ("release", "debug")
    ]
    for c in candidates:
        if c and Path(c).is_file():
            return Path(c)
    found = shutil.which("batten")
    if found:
        return Path(found)
    pytest.fail(
        "the batten CLI is needed for the parity tests: `cargo build --release -p batten-cli` "
        "at the repository root, or set BATTEN_CLI"
    )


def run_cli(cli: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(cli), *args], capture_output=True, text=True, check=False)
