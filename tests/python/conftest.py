"""Shared fixtures of the Python tests: where the sources and the lcsim program are.

ctest sets LCSIM_SOURCE_DIR and LCSIM_BINARY (python/CMakeLists.txt) and puts the
build tree's package first on PYTHONPATH; run by hand, the source tree is found from
this file and the program from LCSIM_BINARY or build/lcsim.
"""

import os
import pathlib

import pytest

SOURCE = pathlib.Path(os.environ.get("LCSIM_SOURCE_DIR",
                                     pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def robots():
    return SOURCE / "robots"


@pytest.fixture(scope="session")
def lcsim_binary():
    exe = pathlib.Path(os.environ.get("LCSIM_BINARY", SOURCE / "build" / "lcsim"))
    if not exe.is_file():
        pytest.fail(f"the lcsim program is not built: {exe} (set LCSIM_BINARY)")
    return exe
