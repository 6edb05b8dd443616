"""Shared fixtures: the shared models and the Rust reference (the formfind example binary).

Tests that need either fail instead of skipping when CI or VSR_REQUIRE_MODELS=1 is set, so that
CI never passes without having compared against the real models.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Optional

import pytest

REPO = Path(__file__).resolve().parents[2]
MODEL_NAMES = (
    "free_vault",
    "dome_with_doors",
    "lilium",
    "cheese",
    "four_holes",
    "neumunster",
    "hex",
    "three_pillar",
    "vault_pq",
)


def required() -> bool:
    """True where a missing model or reference binary is a failure (CI)."""
    return bool(os.environ.get("CI")) or os.environ.get("VSR_REQUIRE_MODELS") == "1"


def missing(what: str) -> None:
    """Fails in CI, skips elsewhere."""
    if required():
        pytest.fail(f"{what} (required: CI or VSR_REQUIRE_MODELS=1 is set)")
    pytest.skip(what)


def models_dir() -> Path:
    return Path(os.environ.get("VSR_MODELS", REPO.parent / "shared" / "data" / "models"))


@pytest.fixture(scope="session")
def models() -> Path:
    path = models_dir()
    if not all((path / f"{n}.obj").is_file() for n in MODEL_NAMES):
        missing(f"the shared models are not in {path}")
    return path


def formfind_binary() -> Optional[Path]:
    """VSR_FORMFIND, or the newest formfind example cargo built for this checkout."""
    given = os.environ.get("VSR_FORMFIND")
    if given:
        return Path(given)
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    built = [target / p / "examples" / "formfind" for p in ("release", "debug")]
    built = [b for b in built if b.is_file()]
    return max(built, key=lambda b: b.stat().st_mtime) if built else None


@pytest.fixture(scope="session")
def formfind() -> Path:
    binary = formfind_binary()
    if binary is None or not binary.is_file():
        missing(
            "the Rust reference is missing: build it with `cargo build --example formfind` "
            "or set VSR_FORMFIND"
        )
    return binary


SQUARE_POSITIONS = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.3]]
SQUARE_FACES = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
SQUARE_ANCHORED = [0, 1, 2, 3]
