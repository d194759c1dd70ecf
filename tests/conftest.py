"""Shared test fixtures: where the real strong-motion records live."""
from __future__ import annotations

import pathlib

import pytest

#: ``../shared/records/raw`` beside the project checkout
SHARED_RECORDS = pathlib.Path(__file__).resolve().parents[1].parent / "shared" / "records" / "raw"


@pytest.fixture
def shared_records() -> pathlib.Path:
    """Folder of the real records; the test is skipped where ``../shared`` is absent."""
    if not SHARED_RECORDS.is_dir():
        pytest.skip(f"real records not available: {SHARED_RECORDS} is absent (../shared beside the checkout)")
    return SHARED_RECORDS


def shared_record(name: str) -> pathlib.Path:
    """Path of one shared record, skipping the test where it is absent."""
    path = SHARED_RECORDS / name
    if not path.is_file():
        pytest.skip(f"real record not available: {path} is absent (../shared beside the checkout)")
    return path
