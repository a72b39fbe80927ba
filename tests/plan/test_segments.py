"""Segment distances against a dense sampling of the two segments, and the grid finding every
segment within a distance, as a look at all of them does."""

from __future__ import annotations

import numpy as np
import pytest

from cadkg.geometry.segments import close_pairs, segment_distances


def _sampled(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> float:
    s = np.linspace(0.0, 1.0, 801)
    a, b = p1 + np.outer(s, q1 - p1), p2 + np.outer(s, q2 - p2)
    return float(np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2).min())


def test_distances_match_sampling_for_crossing_parallel_and_degenerate_segments() -> None:
    rng = np.random.default_rng(7)
    rows = []
    for i in range(120):
        p1, q1, p2, q2 = (rng.normal(size=3) for _ in range(4))
        if i % 5 == 0:
            q1 = p1.copy()  # a point
        if i % 6 == 0:
            q2 = p2 + (q1 - p1) * 0.5  # parallel
        rows.append((p1, q1, p2, q2))
    computed = segment_distances(*(np.array([r[k] for r in rows]) for k in range(4)))
    sampled = np.array([_sampled(*r) for r in rows])
    assert np.all(computed <= sampled + 1e-12)
    assert np.all(sampled - computed < 0.01)  # sampling is within a step of the true minimum


@pytest.mark.parametrize(("filed_scale", "query_scale"), [(0.03, 0.05), (0.01, 0.4), (0.3, 0.001)])
def test_the_grid_finds_what_checking_every_pair_finds(filed_scale: float, query_scale: float) -> None:
    # Queries longer than the filed segments, much longer (spanning many cubes), and shorter.
    rng = np.random.default_rng(3)
    lows = rng.uniform(-0.5, 0.5, size=(300, 3))
    filed = np.stack([lows, lows + rng.normal(scale=filed_scale, size=(300, 3))], axis=1)
    starts = rng.uniform(-0.5, 0.5, size=(200, 3))
    queries = np.stack([starts, starts + rng.normal(scale=query_scale, size=(200, 3))], axis=1)
    near_q, near_n, _ = close_pairs(queries, filed, 0.01, chunk=64)
    found = list(zip(near_q.tolist(), near_n.tolist(), strict=True))
    pairs = [(q, n) for q in range(len(queries)) for n in range(len(filed))]
    a, b = (np.array([queries[q][k] for q, _ in pairs]) for k in (0, 1))
    c, d = (np.array([filed[n][k] for _, n in pairs]) for k in (0, 1))
    every = [pair for pair, gap in zip(pairs, segment_distances(a, b, c, d), strict=True) if gap < 0.01]
    assert found == every and found
