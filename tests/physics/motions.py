"""The real ground motions the record-level reference comparisons share (imported, never collected): a block of
R = 2 m, alpha = 0.25 and the strong part of a processed record, scaled to a multiple of its uplift PGA."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from rockfrag.blocks import Block
from rockfrag.processing import load_recipe, process_record
from rockfrag.records import load_records

BLOCK = Block(name="reference", R=2.0, alpha=0.25, mass=5000.0)  # b/h = 0.255
SAMPLES = 2000  # the strong part: 20 s of Bolu (dt 0.01 s), 10 s of Capitola (dt 0.005 s)
TAIL = 5.0  # s of free motion after the truncated record


@lru_cache(maxsize=None)
def ground_motion(record_id):
    """Processed record (default recipe), truncated to its strong part: (ag [m/s^2], dt [s])."""
    records, failures = load_records([record_id])
    assert not failures, failures
    processed = process_record(records[0], load_recipe())
    return processed.acceleration[:SAMPLES].copy(), processed.dt


def case_motion(record_id, scale):
    """The record scaled so that its PGA is ``scale`` times Housner's uplift acceleration g tan(alpha)."""
    ag, dt = ground_motion(record_id)
    return ag * scale * BLOCK.uplift_acceleration() / np.max(np.abs(ag)), dt
