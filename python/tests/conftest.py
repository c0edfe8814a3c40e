"""Shared fixtures: the repository's scenes and the `glint` command the package is checked
against (GLINT_BIN, else the newest cargo build in target/)."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def cornell():
    return ROOT / "scenes" / "cornell.toml"


@pytest.fixture(scope="session")
def cli():
    """Runs the glint command line; returns the CompletedProcess (text output)."""
    binary = os.environ.get("GLINT_BIN")
    if not binary:
        # The newest cargo build: an older one may predate the checkout's sources.
        built = [ROOT / "target" / p / "glint" for p in ("release", "debug")]
        built = [b for b in built if b.is_file()]
        binary = str(max(built, key=lambda b: b.stat().st_mtime)) if built else None
    if binary is None or not os.path.isfile(binary):
        pytest.fail("no glint binary: build it (cargo build) or set GLINT_BIN")

    def run(*args, check=True):
        result = subprocess.run(
            [binary, *map(str, args)], capture_output=True, text=True, timeout=300
        )
        if check and result.returncode != 0:
            raise AssertionError(f"glint {args} failed ({result.returncode}): {result.stderr}")
        return result

    return run
