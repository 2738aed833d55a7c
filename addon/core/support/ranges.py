"""Runs of consecutive indices, built without a Python loop."""

from __future__ import annotations

import numpy as np


def concatenated_ranges(starts, lengths) -> np.ndarray:
    """start, start + 1, ..., start + length - 1 of every (start, length), one run after another."""
    lengths = np.asarray(lengths, dtype=np.int64)
    offsets = np.cumsum(lengths) - lengths
    return np.repeat(np.asarray(starts, dtype=np.int64) - offsets, lengths) + np.arange(int(lengths.sum()))


def matching_rows(sorted_keys: np.ndarray, queries) -> tuple:
    """(rows, counts): the rows of ``sorted_keys`` (ascending) equal to each query, the queries'
    rows one after another, and how many each query has."""
    first = np.searchsorted(sorted_keys, queries, side="left")
    counts = np.searchsorted(sorted_keys, queries, side="right") - first
    return concatenated_ranges(first, counts), counts
