"""Fixtures of the fiblet Python tests: the shared test data, the fiblet CLI
(an independent path to the same files), and .fft files made from the shared
.tck files once per session."""
import os
import subprocess
from pathlib import Path

import pytest

SHARED = Path(os.environ.get("FIBLET_SHARED_DATA", Path(__file__).resolve().parents[3] / "shared" / "data"))
CLI = os.environ.get("FIBLET_CLI", "fiblet")


@pytest.fixture(scope="session")
def shared():
    if not SHARED.is_dir():
        pytest.skip(f"shared test data not found at {SHARED}")
    return SHARED


@pytest.fixture(scope="session")
def cli():
    return CLI


@pytest.fixture(scope="session")
def compressed(shared, tmp_path_factory):
    """compressed(name) -> (fft path, tck path): shared/data/NAME.tck
    compressed by the CLI (cached for the session)."""
    out = tmp_path_factory.mktemp("fft")
    cache = {}

    def make(name):
        if name not in cache:
            tck = shared / f"{name}.tck"
            fft = out / f"{name.replace('/', '_')}.fft"
            subprocess.run([CLI, "compress", "-q", str(tck), "-o", str(fft)], check=True)
            cache[name] = (fft, tck)
        return cache[name]

    return make
