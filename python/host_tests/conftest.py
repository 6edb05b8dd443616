"""Fixtures of the host tests (run by .ci/hosts, each file in the venv its host needs).

A host that VSR_REQUIRE_HOSTS names (.ci/hosts sets it to the hosts it was asked to run) must
be there: its tests fail instead of skipping without it. The shared models and the formfind
example come from python/tests/conftest.py, required as there.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

_spec = importlib.util.spec_from_file_location(
    "voussoir_tests_conftest", Path(__file__).resolve().parents[1] / "tests" / "conftest.py"
)
shared = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(shared)

REPO = shared.REPO
MODEL_NAMES = shared.MODEL_NAMES
models = shared.models
formfind = shared.formfind


def host_required(host: str) -> bool:
    return host in os.environ.get("VSR_REQUIRE_HOSTS", "").replace(",", " ").split()


def host_missing(host: str, what: str) -> None:
    """Fails where VSR_REQUIRE_HOSTS names `host`, skips elsewhere."""
    if host_required(host):
        pytest.fail(f"{what} (required: VSR_REQUIRE_HOSTS names {host})")
    pytest.skip(what)


def host_program(host: str, program: str) -> str:
    path = shutil.which(program)
    if path is None:
        host_missing(host, f"`{program}` is not on PATH")
    return path


def host_import(host: str, module: str):
    try:
        return importlib.import_module(module)
    except ImportError as e:
        host_missing(host, f"cannot import {module}: {e}")


def read_obj(path: Path):
    """(vertices float64, faces int64) of an OBJ file of triangles (1-based, `v`/`f` lines)."""
    vertices, faces = [], []
    for line in path.read_text().splitlines():
        fields = line.split()
        if fields and fields[0] == "v":
            vertices.append([float(x) for x in fields[1:4]])
        elif fields and fields[0] == "f":
            faces.append([int(f.split("/")[0]) - 1 for f in fields[1:]])
    return np.array(vertices), np.array(faces, dtype=np.int64)
