"""Shared fixtures: where the real data lives, and skipping cleanly when it does not."""
from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
REALDATA = (ROOT / ".." / "shared" / "realdata").resolve()
SEEDS = (ROOT / ".." / "shared" / "seeds").resolve()


@pytest.fixture(scope="session")
def realdata() -> Path:
    """``../shared/realdata`` beside the checkout; skip with a reason when absent."""
    if not REALDATA.is_dir():
        pytest.skip(f"real data folder {REALDATA} is absent (a user's clone has no "
                    "../shared/realdata; CI always has it)")
    return REALDATA


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return ROOT
