"""A plane layout of a harness topology from its segment lengths, for a graph without coordinates.

Classical multidimensional scaling of the shortest-path distances (segment lengths as edge
weights): on a tree, which a harness topology nearly always is, distances along the harness
come out close to the drawing's, so branches keep their proportions. The layout is the same
on every call (no random start). Several pieces are laid out apart, left to right.
"""

from __future__ import annotations

from collections.abc import Sequence

import networkx as nx
import numpy as np

__all__ = ["layout"]

_DEFAULT_LENGTH = 0.1  # metres, for a segment without a length
_MDS_LIMIT = 1500  # above this many nodes of one piece, a spring layout (MDS is quadratic in memory)
_GAP = 0.2


def _piece(graph: nx.Graph, nodes: list[int]) -> np.ndarray:
    if len(nodes) == 1:
        return np.zeros((1, 2))
    sub = graph.subgraph(nodes)
    if len(nodes) > _MDS_LIMIT:
        spread = nx.spring_layout(sub, seed=0, weight=None)
        return np.array([spread[n] for n in nodes]) * float(np.sqrt(len(nodes))) * _DEFAULT_LENGTH
    lengths = dict(nx.all_pairs_dijkstra_path_length(sub, weight="length"))
    distances = np.array([[lengths[a].get(b, 0.0) for b in nodes] for a in nodes])
    squared = distances**2
    centring = np.eye(len(nodes)) - 1.0 / len(nodes)
    gram = -0.5 * centring @ squared @ centring
    values, vectors = np.linalg.eigh(gram)
    top = np.argsort(values)[::-1][:2]
    coords: np.ndarray = vectors[:, top] * np.sqrt(np.clip(values[top], 0.0, None))
    # Eigenvectors have no sign: the first node goes left (and down), so a layout never flips.
    for axis in range(coords.shape[1]):
        if coords[0, axis] > 0:
            coords[:, axis] = -coords[:, axis]
    return coords


def layout(count: int, segments: Sequence[tuple[int, int, float | None]]) -> list[tuple[float, float]]:
    """Plane positions (metres) of ``count`` nodes joined by ``(from, to, length)`` segments.

    >>> [round(x, 3) for x, y in layout(3, [(0, 1, 1.0), (1, 2, 1.0)])]  # a straight line
    [0.0, 1.0, 2.0]
    """
    graph = nx.Graph()
    graph.add_nodes_from(range(count))
    for start, end, length in segments:
        graph.add_edge(start, end, length=float(length) if length else _DEFAULT_LENGTH)
    positions = np.zeros((count, 2))
    offset = 0.0
    for piece in sorted(nx.connected_components(graph), key=lambda p: (-len(p), min(p))):
        nodes = sorted(piece)
        coords = _piece(graph, nodes)
        coords[:, 0] += offset - coords[:, 0].min()
        coords[:, 1] -= coords[:, 1].mean()
        positions[nodes] = coords
        offset = float(coords[:, 0].max()) + _GAP
    return [(float(x), float(y)) for x, y in positions]
